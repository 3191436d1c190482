"""Physical bounds and work budgets (issue 18): huge but finite numbers and oversized requests are refused before
any work starts, naming the field or option, the value and the limit (docs/limits.md)."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

from cli_helpers import assert_user_error, invoke
from conftest import deep_update, minimal_scenario_dict
from vrusim.engine.simulate import simulate
from vrusim.engine.trace_recorder import trace_bytes
from vrusim.errors import UserInputError
from vrusim.limits import env_name, limit
from vrusim.scenario.loading import scenario_from_mapping
from vrusim.studies.compare import compare
from vrusim.sweep.spec import spec_from_mapping

ROOT = Path(__file__).resolve().parents[1]
PEDESTRIAN = ROOT / "scenarios" / "paper" / "pedestrian_crossing.yaml"


def _scenario(changes: dict) -> dict:
    return deep_update(minimal_scenario_dict(), changes)


def _write(tmp_path: Path, data: dict, name: str = "scenario.yaml") -> Path:
    path = tmp_path / name
    path.write_text(yaml.safe_dump(data))
    return path


def _vru_path(*points) -> dict:
    return {"vrus": [{**minimal_scenario_dict()["vrus"][0], "heading_deg": None, "path": [list(p) for p in points]}]}


def _refusal(data: dict) -> str:
    with pytest.raises(UserInputError) as info:
        scenario_from_mapping(data)
    return str(info.value)


# --- the fuzzing campaign's examples ---------------------------------------------------------------------------


def test_a_route_of_1e308_m_is_refused_not_an_overflow(tmp_path):
    path = _write(tmp_path, _scenario({"ego": {"route": {"length_m": 1.0e308}}}))
    result = invoke("run", path)
    assert_user_error(result, "ego.route.length_m: 1e+308 m exceeds the limit of 100,000", "VRUSIM_LIMIT_LENGTH_M")


def test_a_path_point_1e15_m_away_is_refused_not_allocated(tmp_path):
    path = _write(tmp_path, _scenario(_vru_path((1e15, 0.0))))
    assert_user_error(invoke("run", path), "vrus[0].path[0].x_m: 1e+15 m exceeds the limit of 100,000")


@pytest.mark.parametrize(
    ("changes", "field"),
    [
        ({"ego": {"start": {"x_m": 2**64}}}, "ego.start.x_m"),
        (_vru_path((0.0, 2**64)), "vrus[0].path[0].y_m"),
        ({"v2x": {"rsu": [2**64, 0.0]}}, "v2x.rsu.x_m"),
        ({"obstacles": [{"centre": {"x_m": -(2**64), "y_m": 0.0}, "length_m": 4.0, "width_m": 2.0}]}, "obstacles"),
    ],
)
def test_a_coordinate_of_2_to_the_64_is_refused_naming_the_field(changes, field):
    assert f"{field}" in _refusal(_scenario(changes)) and "VRUSIM_LIMIT_COORDINATE_M" in _refusal(_scenario(changes))


def test_a_path_coordinate_of_1e6_m_is_refused_and_the_variable_raises_the_limit(monkeypatch):
    data = _scenario(_vru_path((1e6, 50.0)))
    assert "vrus[0].path[0].x_m: 1,000,000 m exceeds the limit of 100,000" in _refusal(data)
    monkeypatch.setenv(env_name("coordinate_m"), "2000000")
    monkeypatch.setenv(env_name("length_m"), "2000000")
    assert scenario_from_mapping(data).vrus[0].path[0].x_m == 1e6  # validated only: not run


def test_a_zigzag_path_is_refused_by_its_total_length():
    data = _scenario(_vru_path((90_000.0, 50.0), (0.0, 50.0), (90_000.0, 50.0)))
    assert "vrus[0].path: total length 269,500 m exceeds the limit of 100,000" in _refusal(data)


def test_speeds_and_accelerations_are_bounded():
    assert "ego.cruise_speed_mps: 200 m/s exceeds the limit of 150" in _refusal(
        _scenario({"ego": {"cruise_speed_mps": 200.0}})
    )
    assert "ego.max_decel_mps2: 1e+300 m/s^2 exceeds the limit of 10,000" in _refusal(
        _scenario({"ego": {"max_decel_mps2": 1e300}})
    )
    assert "planner.params" not in _refusal(_scenario({"ego": {"max_decel_mps2": 1e300}}))


def test_planner_parameters_are_bounded_too():
    from vrusim.planners.fsm import FsmParams

    with pytest.raises(ValueError, match="emergency_decel_mps2"):
        FsmParams(emergency_decel_mps2=1e308)


def test_compare_with_1e11_seeds_is_refused_before_running(tmp_path):
    result = invoke("compare", PEDESTRIAN, "--seeds", "100000000000")
    assert_user_error(result, "--seeds: 100,000,000,000 seeds", "200,000,000,000 runs exceeds the limit of 100,000")
    assert "VRUSIM_LIMIT_COMPARE_RUNS" in result.output
    base = scenario_from_mapping(minimal_scenario_dict())
    with pytest.raises(UserInputError, match="--seeds: 100,001 seeds x 1 V2X settings x 1 planners"):
        compare(base, ["none"], ["off"], seeds=100_001)


def test_a_trace_at_the_most_steps_is_refused_before_the_run(tmp_path):
    path = _write(tmp_path, _scenario({"sim": {"dt_s": 0.00036, "duration_s": 3600.0}}))
    result = invoke("run", path, "--trace", tmp_path / "trace.csv")
    # 2 copies x 10^7 steps x (t + 14 ego columns + 6 VRU columns) x 8 bytes
    assert_user_error(result, "--trace / trace=True: 10,000,000 steps", "3,360,000,000 bytes", "TRACE_BYTES raises")
    assert not (tmp_path / "trace.csv").exists()


def test_the_trace_estimate_bounds_what_is_recorded(monkeypatch):
    scenario = scenario_from_mapping(minimal_scenario_dict())
    run = simulate([scenario, scenario], trace=True)
    recorded = sum(column.nbytes for column in run.trace.values())
    estimate = trace_bytes(run.params.n_steps, 2, run.params.vru_slots)
    assert recorded <= estimate / 2 <= 2 * recorded  # one copy estimated within a factor 2, an upper bound
    monkeypatch.setenv(env_name("trace_bytes"), str(estimate - 1))
    with pytest.raises(UserInputError, match="VRUSIM_LIMIT_TRACE_BYTES raises it"):
        simulate([scenario, scenario], trace=True)
    simulate([scenario, scenario])  # without a trace the budget does not apply
    monkeypatch.setenv(env_name("trace_bytes"), str(estimate))
    assert simulate([scenario, scenario], trace=True).steps == run.steps


def test_variant_steps_of_one_batch_are_budgeted(monkeypatch):
    scenario = scenario_from_mapping(minimal_scenario_dict())  # 500 steps
    monkeypatch.setenv(env_name("batch_variant_steps"), "999")
    with pytest.raises(UserInputError, match="2 variants x 500 steps of one batch run: 1,000 variant-steps exceeds"):
        simulate([scenario, scenario])
    assert simulate([scenario]).steps == 500


def test_the_path_tables_are_budgeted_before_sampling(tmp_path, monkeypatch):
    """64 VRU paths of 99,980 m each (a 6.7 kB file) asked 32 million samples and more than 5 GB: the table of
    distinct paths x the longest path's samples is counted before anything is sampled."""
    crossing = {**minimal_scenario_dict()["vrus"][0], "heading_deg": None}
    vrus = [
        {**crossing, "start": [float(i), -10.0], "path": [[float(i), 49_980.0], [float(i), -10.0]]} for i in range(64)
    ]
    path = _write(tmp_path, _scenario({"vrus": vrus, "sim": {"duration_s": 0.1}}))
    expected = "vrus[].path: 64 distinct paths x the longest, 99,980 m, sampled every 0.2 m: 31,993,664 samples"
    assert_user_error(invoke("run", path), expected, "exceeds the limit of 10,000,000", "PATH_SAMPLES raises it")
    monkeypatch.setenv(env_name("path_samples"), "2000")  # the minimal scenario: a 200 m route, 1,001 samples
    with pytest.raises(
        UserInputError, match=r"ego\.route: 1 distinct paths x the longest, 400 m, sampled every 0.2 m: 2,001 samples"
    ):
        simulate([scenario_from_mapping(_scenario({"ego": {"route": {"length_m": 400.0}}}))])
    simulate([scenario_from_mapping(_scenario({}))])


# --- sweeps --------------------------------------------------------------------------------------------------


def _spec(parameters: dict, samples: int = 1) -> dict:
    return {"base": str(PEDESTRIAN), "parameters": parameters, "samples": samples, "seed": 1}


@pytest.mark.parametrize(
    "parameter",
    [
        {"uniform": [10, 200]},
        {"truncated_normal": [10, 1, 0, 151]},
        [10.0, 151.0],
        {"choice": [10.0, 1e9]},
        {"range": [100, 200, 50]},
    ],
)
def test_a_swept_range_beyond_a_bound_is_refused_when_the_spec_is_read(parameter):
    with pytest.raises(UserInputError, match=r"parameters\.ego\.cruise_speed_mps: .* exceeds the limit of 150"):
        spec_from_mapping(_spec({"ego.cruise_speed_mps": parameter}), "sweep.yaml", ROOT)


def test_a_normal_draw_beyond_a_bound_is_refused_before_the_sweep_runs(tmp_path):
    spec = _write(tmp_path, _spec({"ego.cruise_speed_mps": {"normal": [140.0, 10.0]}}, samples=50), "sweep.yaml")
    result = invoke("sweep", spec, "--dry-run", "--out", tmp_path / "out")
    assert_user_error(result, "variant ", "ego.cruise_speed_mps", "exceeds the limit of 150")
    assert not (tmp_path / "out").exists()


def test_sweep_variants_are_budgeted(monkeypatch):
    with pytest.raises(UserInputError, match="samples: 20,000,000 variants exceeds the limit of 10,000,000"):
        spec_from_mapping(_spec({}, samples=20_000_000), "sweep.yaml", ROOT)
    with pytest.raises(UserInputError, match="samples x 3 grid points: 15,000,000 variants exceeds"):
        spec_from_mapping(_spec({"ego.cruise_speed_mps": [8.0, 9.0, 10.0]}, samples=5_000_000), "s.yaml", ROOT)
    with pytest.raises(UserInputError, match=r"linspace: count: 20,000,000 variants exceeds"):
        spec_from_mapping(_spec({"ego.cruise_speed_mps": {"linspace": [1, 2, 20_000_000]}}), "s.yaml", ROOT)
    monkeypatch.setenv(env_name("sweep_variants"), "20000000")
    assert spec_from_mapping(_spec({}, samples=20_000_000), "sweep.yaml", ROOT).samples == 20_000_000


# --- the bounds as a property ----------------------------------------------------------------------------------

BOUNDED_FIELDS = [
    # (path, limit, smallest valid value)
    ("ego.cruise_speed_mps", "speed_mps", 0.0),
    ("ego.route.length_m", "length_m", 1e-9),
    ("sensor.range_m", "length_m", 1e-9),
    ("v2x.rsu.x_m", "coordinate_m", -1e5),
    ("v2x.rsu.y_m", "coordinate_m", -1e5),
    ("ego.max_accel_mps2", "accel_mps2", 1e-9),
]
_BASE = None


def _base():
    global _BASE
    if _BASE is None:
        _BASE = scenario_from_mapping(_scenario({"v2x": {"rsu": [0.0, 10.0]}}))
    return _BASE


@settings(max_examples=150, deadline=None)
@given(st.sampled_from(BOUNDED_FIELDS), st.floats(0, 1, allow_nan=False))
def test_any_value_within_a_bound_validates(field, fraction):
    path, name, low = field
    value = max(low, -limit(name)) + fraction * (limit(name) - max(low, -limit(name)))
    assert _base().replace(**{path: value}) is not None


@settings(max_examples=150, deadline=None)
@given(st.sampled_from(BOUNDED_FIELDS), st.data())
def test_any_finite_value_beyond_a_bound_is_refused_naming_the_field(field, data):
    path, name, low = field
    value = data.draw(st.floats(min_value=math.nextafter(limit(name), math.inf), max_value=sys.float_info.max))
    value = -value if low < 0 and data.draw(st.booleans()) else value
    with pytest.raises(UserInputError) as info:
        _base().replace(**{path: value})
    assert f"  {path}: " in str(info.value) and f"exceeds the limit of {limit(name):,.0f}" in str(info.value)
