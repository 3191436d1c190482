"""VRU motion models by name: the built-in `point_mass` is registered and packing goes through the registry."""

from __future__ import annotations

import math

import pytest

from vrusim.sim.params import pack
from vrusim.sim.vru import registry
from vrusim.sim.vru.point_mass import pack_point_mass
from vrusim.sim.vru.registry import (
    POINT_MASS,
    VruMotionRow,
    register_vru_motion,
    unregister_vru_motion,
    vru_motion,
    vru_motion_entries,
)

BRAKING = {"type": "cyclist", "start": {"x_m": 20.0, "y_m": -5.0}, "heading_deg": 90.0, "top_speed_mps": 4.0,
           "brake": {"after_trigger_s": 1.5, "decel_mps2": 3.0}}  # fmt: skip


def _fixed(vru) -> VruMotionRow:
    return VruMotionRow(1.25, 0.5, 0.75, 0.25, 2.0, 1.0)


def test_the_point_mass_model_is_registered_and_packs_a_vru(make_scenario):
    assert vru_motion(POINT_MASS).pack is pack_point_mass and POINT_MASS in vru_motion_entries()
    (vru,) = make_scenario({"vrus": [BRAKING]}).vrus
    assert pack_point_mass(vru) == (4.0, vru.accel_mps2, 0.0, 0.0, 1.5, 3.0)
    batch = pack([make_scenario({"vrus": [BRAKING]}), make_scenario()])
    assert batch.vru_top_speed_mps[0, 0] == 4.0
    assert (batch.vru_brake_after_s[0, 0], batch.vru_brake_decel_mps2[0, 0]) == (1.5, 3.0)
    assert (batch.vru_brake_after_s[1, 0], batch.vru_brake_decel_mps2[1, 0]) == (math.inf, 0.0)  # no brake


def test_packing_uses_the_registered_entry(make_scenario, monkeypatch):
    monkeypatch.setitem(registry._ENTRIES, POINT_MASS, registry.VruMotionEntry(POINT_MASS, _fixed, None))
    batch = pack([make_scenario()])
    packed = (
        batch.vru_top_speed_mps, batch.vru_max_accel_mps2, batch.vru_tau_s, batch.vru_initial_speed_mps,
        batch.vru_brake_after_s, batch.vru_brake_decel_mps2,
    )  # fmt: skip
    assert tuple(float(a[0, 0]) for a in packed) == _fixed(None)


def test_a_registered_model_is_found_by_name_until_unregistered():
    entry = register_vru_motion("fixed", _fixed)
    try:
        assert vru_motion("fixed") is entry and vru_motion_entries()["fixed"] is entry
        with pytest.raises(ValueError, match="'fixed' is already registered"):
            register_vru_motion("fixed", _fixed)
    finally:
        unregister_vru_motion("fixed")
    assert "fixed" not in vru_motion_entries()
    with pytest.raises(ValueError, match=r"'fixed' is not registered \(known: point_mass"):
        vru_motion("fixed")
