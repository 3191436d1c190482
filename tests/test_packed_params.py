"""After packing, the engine's parameters hold plain arrays and values only: no pydantic model, no Scenario."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from pydantic import BaseModel

from vrusim.engine.simulate import simulate
from vrusim.metrics.summary import summary_rows
from vrusim.paper.cases import paper_scenarios
from vrusim.sim.params import BatchParams, pack
from vrusim.sim.sensing.sensor_params import pack_sensor


def _models_inside(value, where: str = "params") -> list[str]:
    """Paths of every pydantic model reachable from `value` (dataclass fields, mappings, sequences)."""
    if isinstance(value, BaseModel):
        return [where]
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return [
            p for f in dataclasses.fields(value) for p in _models_inside(getattr(value, f.name), f"{where}.{f.name}")
        ]
    if isinstance(value, Mapping):
        return [p for k, v in value.items() for p in _models_inside(v, f"{where}[{k!r}]")]
    if isinstance(value, list | tuple) or (isinstance(value, np.ndarray) and value.dtype == object):
        return [p for i, v in enumerate(value) for p in _models_inside(v, f"{where}[{i}]")]
    return []


@pytest.fixture(scope="module")
def realistic():
    """The paper's cases with V2X on over a lossy, late channel and a noisy, late sensor, AEB parameters given."""
    scenarios = []
    for _, v2x, scenario in paper_scenarios():
        if not v2x:
            continue
        data = scenario.model_dump()
        data["v2x"]["channel"] = "lossy"
        data["sensor"].update(latency_s=0.1, detection_probability=0.9, position_sigma_m=0.2)
        data["planner"] = {"name": "aeb", "params": {"warning_ttc_s": 2.2}}
        scenarios.append(type(scenario).model_validate(data))
    return scenarios


def test_batch_params_keep_no_scenario_and_no_pydantic_model(realistic):
    assert "scenarios" not in {field.name for field in dataclasses.fields(BatchParams)}
    assert _models_inside(pack(realistic)) == []


def test_the_probe_finds_a_model_where_there_is_one(realistic):
    """The check above can fail: a model hidden in a field is found."""
    params = dataclasses.replace(pack(realistic), planner_params=[{"nested": realistic[0].sensor}] * 3)
    assert _models_inside(params) == ["params.planner_params[0]['nested']"] + [
        f"params.planner_params[{i}]['nested']" for i in (1, 2)
    ]


def test_planner_params_are_read_only_copies(realistic):
    params = pack(realistic)
    assert params.planner_params[0] == {"warning_ttc_s": 2.2}
    with pytest.raises(TypeError):
        params.planner_params[0]["warning_ttc_s"] = 9.0  # type: ignore[index]
    assert params.names == [s.name for s in realistic]
    assert params.score_profiles == [s.metrics.profile for s in realistic]


def test_packed_settings_follow_the_scenarios(realistic):
    params = pack(realistic)
    assert params.sensor.latency_steps.tolist() == [10, 10, 10]  # 0.1 s at dt 0.01 s
    assert not params.sensor.ideal.any() and not params.channel.ideal.any()
    assert params.channel.cfg.shape[0] == params.size == 3


def test_a_run_from_packed_params_equals_a_run_from_scenarios(realistic):
    """The engine needs nothing but the packed parameters (realistic sensor and channel, AEB parameters)."""
    from_scenarios = summary_rows(simulate(realistic))
    from_params = summary_rows(simulate(pack(realistic)))
    assert from_params == from_scenarios
    assert [row["planner"] for row in from_params] == ["aeb"] * 3


@settings(deadline=None, max_examples=60)
@given(
    st.lists(
        st.fixed_dictionaries(
            {
                "latency_s": st.floats(0.0, 0.5),
                "frame_rate_hz": st.none() | st.floats(0.5, 200.0),
                "detection_probability": st.sampled_from([1.0, 0.999, 0.5]),
                "position_sigma_m": st.sampled_from([0.0, 0.1]),
                "velocity_sigma_mps": st.sampled_from([0.0, 0.1]),
            }
        ),
        min_size=1,
        max_size=6,
    ),
    st.sampled_from([0.01, 0.02, 0.005, 0.1]),
)
def test_packed_sensor_settings_equal_the_per_scenario_rules(sensors, dt_s):
    """`pack_sensor` works on arrays; each row equals the documented per-scenario rule (docs/models.md, "Sensor
    model"), written here with Python floats: L = round(latency / dt), F = max(1, round(1 / (rate dt))), halves
    up; ideal = exact reports, L = 0 and F = 1."""

    def steps(duration_s: float) -> int:
        return math.floor(duration_s / dt_s + 0.5 + 1e-9)

    base = paper_scenarios()[0][2].model_dump()
    scenarios = []
    for sensor in sensors:
        data = base | {"sensor": base["sensor"] | sensor, "sim": base["sim"] | {"dt_s": dt_s}}
        scenarios.append(type(paper_scenarios()[0][2]).model_validate(data))
    packed = pack_sensor(scenarios)
    latency = [steps(s.sensor.latency_s) for s in scenarios]
    frame = [1 if s.sensor.frame_rate_hz is None else max(1, steps(1.0 / s.sensor.frame_rate_hz)) for s in scenarios]
    exact = [s.sensor.detection_probability == 1.0 and s.sensor.position_sigma_m == s.sensor.velocity_sigma_mps == 0.0
             for s in scenarios]  # fmt: skip
    assert packed.latency_steps.tolist() == latency
    assert packed.frame_steps.tolist() == frame
    assert packed.ideal.tolist() == [e and lat == 0 and f == 1 for e, lat, f in zip(exact, latency, frame, strict=True)]
