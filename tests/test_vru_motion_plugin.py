"""A VRU motion model added by a module outside vrusim (tests/extra_vru_motion.py): chosen by `vrus[k].motion`,
packed and stepped through the registry; unknown or mixed models are refused naming the field."""

from __future__ import annotations

import numpy as np
import pytest

import extra_vru_motion
import vrusim
from vrusim.engine.simulate import simulate
from vrusim.errors import UserInputError
from vrusim.metrics.summary import summary_rows
from vrusim.sim.params import pack

CROSSING = {"type": "pedestrian", "start": {"x_m": 30.0, "y_m": -4.0}, "heading_deg": 90.0, "top_speed_mps": 1.5}


@pytest.fixture
def drift():
    extra_vru_motion.register()
    yield extra_vru_motion.NAME
    extra_vru_motion.unregister()


def _with(make_scenario, motion: str | None, name: str = "test"):
    vru = CROSSING | ({} if motion is None else {"motion": motion})
    return make_scenario({"name": name, "vrus": [vru], "sim": {"duration_s": 2.0, "stop_on_collision": False}})


def test_the_default_is_the_point_mass(make_scenario):
    scenario = _with(make_scenario, None)
    assert scenario.vrus[0].motion == "point_mass" and pack([scenario]).vru_motion == "point_mass"


def test_a_plugin_model_moves_the_vrus_of_its_batch(make_scenario, drift):
    run = simulate([_with(make_scenario, drift)], trace=True)
    assert run.params.vru_motion == drift
    y, x = run.trace["vru_y_m"][:, 0, 0], run.trace["vru_x_m"][:, 0, 0]
    steps = np.arange(1, y.size + 1)
    np.testing.assert_allclose(y, -4.0 + extra_vru_motion.DRIFT_Y_MPS * 0.01 * steps, rtol=0, atol=1e-9)
    assert np.all(x == 30.0)  # the plug-in ignores the path's heading: it really is the plug-in that moved them
    point_mass = simulate([_with(make_scenario, None)], trace=True).trace["vru_y_m"][:, 0, 0]
    assert not np.allclose(point_mass, y)
    assert summary_rows(run)[0]["scenario"] == "test"


def test_an_unknown_model_is_refused_naming_the_field(make_scenario):
    with pytest.raises(UserInputError, match=r"^test: vrus\[0\]\.motion: unknown VRU motion model 'walk'; expected"):
        pack([_with(make_scenario, "walk")])


def test_one_batch_moves_its_vrus_by_one_model(make_scenario, drift):
    with pytest.raises(UserInputError, match=r"one batch moves all its VRUs by one motion model, got drift, point"):
        pack([_with(make_scenario, drift), _with(make_scenario, None, "other")])


def test_a_model_without_a_step_cannot_run(make_scenario):
    vrusim.register_vru_motion("pack_only", extra_vru_motion.pack)
    try:
        with pytest.raises(UserInputError, match="'pack_only' has no step"):
            simulate([_with(make_scenario, "pack_only")])
    finally:
        vrusim.unregister_vru_motion("pack_only")
