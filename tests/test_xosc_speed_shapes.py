"""OpenSCENARIO speed actions with `dynamicsShape` cubic and sinusoidal (issue 19): the hand-written files in
tests/data/xosc/shapes/ import as the VRU motion models `cubic` / `sinusoidal`, run with planner `none` and match
hand-derived motion (<= 0.01 s, <= 0.02 m); export -> import round-trips; a shaped ego change, two shapes in one
file and a shaped stop that cannot be represented are refused (exit 2) naming the element and its line."""

from __future__ import annotations

import math
import shutil
import tempfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from vrusim.engine.simulate import simulate
from vrusim.formats.xosc_import import read_xosc
from vrusim.interop.openscenario import export_openscenario
from vrusim.scenario.loading import scenario_from_mapping
from vrusim.sources import apply_planner_and_seed
from xosc_helpers import refused_at

DATA = Path(__file__).parent / "data" / "xosc" / "shapes"
ACTIONS = Path(__file__).parent / "data" / "xosc" / "actions"
VRU_Y0_M = -6.14
"""Every VRU starts at y = -6.14 m and walks along -y; the ego drives along y = -1.75 m at 10 m/s."""
DISTANCE_TOL_M = 0.02


def _cubic_area(s: float) -> float:
    """Integral of the cubic shape h(s) = 3s^2 - 2s^3 from 0 to s."""
    return s**3 - s**4 / 2


def _sine_area(s: float) -> float:
    """Integral of the sinusoidal shape h(s) = (1 - cos(pi s)) / 2 from 0 to s."""
    return (s - math.sin(math.pi * s) / math.pi) / 2


def _trace(path: Path) -> dict[str, np.ndarray]:
    return simulate([apply_planner_and_seed(read_xosc(path), "none")], trace=True).trace


def _at(trace: dict[str, np.ndarray], key: str, t_s: float, vru: int = 0) -> float:
    return float(np.interp(t_s, trace["t_s"], trace[key][:, 0, vru]))


def _walked(trace: dict[str, np.ndarray], t_s: float, vru: int = 0) -> float:
    return VRU_Y0_M - _at(trace, "vru_y_m", t_s, vru)


def _copy(tmp_path: Path, source: Path, old: str = "", new: str = "") -> Path:
    """`source` (with its road) in `tmp_path`, `old` replaced once by `new`."""
    shutil.copy(source.parent / "road.xodr", tmp_path / "road.xodr")
    text = source.read_text()
    assert old in text, old
    path = tmp_path / source.name
    path.write_text(text.replace(old, new, 1))
    return path


def _refused(path: Path, marker: str, *words: str) -> str:
    """The refusal naming the file, the line of the last `marker` and `words`."""
    return refused_at(path, marker, *words, last=True)


# --------------------------------------------------------------------------------------------- supported


def test_a_cubic_change_over_a_time():
    assert read_xosc(DATA / "cubic_time.xosc").vrus[0].motion == "cubic"
    trace = _trace(DATA / "cubic_time.xosc")  # at t = 1 s, 0 -> 2 m/s over T = 2 s
    assert abs(_walked(trace, 1.0)) < DISTANCE_TOL_M
    assert abs(_walked(trace, 2.0) - 2.0 * 2.0 * _cubic_area(0.5)) < DISTANCE_TOL_M  # 0.375 m at half-time
    assert abs(_at(trace, "vru_speed_mps", 2.0) - 1.0) < 1e-6
    assert abs(_walked(trace, 3.0) - (0.0 + 2.0) / 2 * 2.0) < DISTANCE_TOL_M
    assert abs(_at(trace, "vru_speed_mps", 3.0) - 2.0) < 1e-6
    assert abs(_walked(trace, 5.0) - (2.0 + 2.0 * 2.0)) < DISTANCE_TOL_M


def test_a_cubic_change_over_a_distance_reaches_its_speed_after_that_distance():
    trace = _trace(DATA / "cubic_distance.xosc")  # 0 -> 2 m/s over 3 m: T = 2 x 3 / (0 + 2) = 3 s
    assert abs(_walked(trace, 4.0) - 3.0) < DISTANCE_TOL_M
    assert abs(_at(trace, "vru_speed_mps", 4.0) - 2.0) < 1e-6
    assert abs(_at(trace, "vru_speed_mps", 2.5) - 1.0) < 1e-6
    assert _at(trace, "vru_speed_mps", 3.99) < 2.0  # still changing until then (h'(1) = 0: barely)


def test_a_sinusoidal_change_at_a_rate_reads_the_rate_as_its_peak():
    scenario = read_xosc(DATA / "sinusoidal_rate.xosc")  # peak pi/2 m/s^2: mean 1 m/s^2, T = 2 s
    assert (scenario.vrus[0].motion, scenario.vrus[0].max_accel_mps2) == ("sinusoidal", pytest.approx(1.0))
    trace = _trace(DATA / "sinusoidal_rate.xosc")
    assert abs(_walked(trace, 1.5) - 2.0 * 2.0 * _sine_area(0.25)) < DISTANCE_TOL_M
    assert abs(_walked(trace, 3.0) - 2.0) < DISTANCE_TOL_M
    accel = np.diff(trace["vru_speed_mps"][:, 0, 0]) / np.diff(trace["t_s"])
    assert abs(accel.max() - math.pi / 2) < 1e-3
    assert abs(trace["t_s"][accel.argmax()] + 0.005 - 2.0) < 0.01  # the peak at half-time (mid-step)


def test_a_cubic_stop_over_a_distance_after_its_start_event():
    scenario = read_xosc(DATA / "cubic_stop.xosc")
    brake = scenario.vrus[0].brake
    assert brake is not None and (brake.after_trigger_s, brake.decel_mps2) == (2.0, 0.75)
    trace = _trace(DATA / "cubic_stop.xosc")  # 0 -> 1.5 m/s over 1 s from t = 1 s; from t = 3 s, 1.5 -> 0 over 2 s
    assert abs(_walked(trace, 2.0) - 0.75) < DISTANCE_TOL_M
    assert abs(_walked(trace, 3.0) - 2.25) < DISTANCE_TOL_M
    assert abs(_walked(trace, 4.0) - (2.25 + 1.5 * (1.0 - 2.0 * _cubic_area(0.5)))) < DISTANCE_TOL_M
    assert abs(_walked(trace, 5.0) - (2.25 + 1.5)) < DISTANCE_TOL_M
    assert _at(trace, "vru_speed_mps", 5.0) == 0.0 and _at(trace, "vru_speed_mps", 4.9) > 0.0


def test_every_vru_of_a_shaped_file_moves_by_its_model_steps_included():
    scenario = read_xosc(DATA / "two_vrus_sinusoidal.xosc")
    assert [v.motion for v in scenario.vrus] == ["sinusoidal", "sinusoidal"]
    trace = _trace(DATA / "two_vrus_sinusoidal.xosc")
    assert abs(_walked(trace, 3.0, 0) - 2.0) < DISTANCE_TOL_M
    assert abs(_walked(trace, 4.0, 1) - 2.0) < DISTANCE_TOL_M  # a step to 1 m/s at t = 2 s


@settings(max_examples=12, deadline=None)
@given(
    shape=st.sampled_from(("cubic", "sinusoidal")),
    dimension=st.sampled_from(("time", "distance", "rate")),
    speed=st.floats(0.5, 4.0),
    amount=st.floats(0.5, 3.0),
)
def test_any_shaped_start_covers_the_mean_speed_times_its_duration(shape, dimension, speed, amount):
    """Over a time T, a distance D (T = 2 D / v1) or at a peak rate r (T = k v1 / r): v1 reached after T, having
    walked v1 T / 2."""
    duration = {
        "time": amount,
        "distance": 2 * amount / speed,
        "rate": {"cubic": 1.5, "sinusoidal": math.pi / 2}[shape] * speed / amount,
    }[dimension]
    assume(duration <= 6.5)  # the change ends inside the 8 s run (it starts at 1 s)
    dynamics = f'<SpeedActionDynamics dynamicsShape="{shape}" dynamicsDimension="{dimension}" value="{amount!r}"/>'
    with tempfile.TemporaryDirectory() as folder:
        cubic = '<SpeedActionDynamics dynamicsShape="cubic" dynamicsDimension="time" value="2.0"/>'
        path = _copy(Path(folder), DATA / "cubic_time.xosc", cubic, dynamics)
        path.write_text(path.read_text().replace('"2.0"/></SpeedActionTarget>', f'"{speed!r}"/></SpeedActionTarget>'))
        trace = _trace(path)
    end_s = 1.0 + duration
    expected = speed * duration / 2 + speed * (end_s - 1.0 - duration)
    assert abs(_walked(trace, end_s) - expected) < DISTANCE_TOL_M
    assert abs(_at(trace, "vru_speed_mps", 1.0 + duration + 0.01) - speed) < 1e-6


@pytest.mark.parametrize("shape", ["cubic", "sinusoidal"])
def test_export_then_import_runs_the_same(tmp_path, make_scenario, shape):
    """A crossing VRU of each shaped model, with a brake from mid-ramp, exported and imported: same motion, same
    contact time and place."""
    vru = {"type": "pedestrian", "start": {"x_m": 30.0, "y_m": -6.0}, "heading_deg": 90.0, "top_speed_mps": 2.5,
           "max_accel_mps2": 0.9, "trigger": {"ego_route_m": 5.0}, "motion": shape,
           "brake": {"after_trigger_s": 2.0, "decel_mps2": 1.2}}  # fmt: skip
    original = make_scenario({"vrus": [vru], "sim": {"duration_s": 6.0}})
    export_openscenario(original, tmp_path, "shaped")
    text = (tmp_path / "shaped.xosc").read_text()
    assert f'dynamicsShape="{shape}"' in text and "Vru0AccelPeak_mps2" in text
    imported = read_xosc(tmp_path / "shaped.xosc")
    assert imported.vrus[0].motion == shape
    assert imported.vrus[0].max_accel_mps2 == pytest.approx(0.9, rel=1e-12)
    imported = scenario_from_mapping(
        imported.model_dump(mode="json") | {"planner": {"name": "none"}, "ego": original.ego.model_dump(mode="json")}
    )
    runs = [simulate([s], trace=True) for s in (original, imported)]
    (a, b) = (run.trace for run in runs)
    assert np.abs(a["vru_y_m"] - b["vru_y_m"]).max() < 1e-6 and np.abs(a["vru_x_m"] - b["vru_x_m"]).max() < 1e-6
    assert bool(runs[0].metrics.collided[0]) == bool(runs[1].metrics.collided[0])


# --------------------------------------------------------------------------------------------- refused

WALK = '<SpeedActionDynamics dynamicsShape="linear" dynamicsDimension="time" value="2.0"/>'


@pytest.mark.parametrize("shape", ["cubic", "sinusoidal"])
def test_a_shaped_ego_change_is_refused(tmp_path, shape):
    path = _copy(tmp_path, ACTIONS / "ego_linear_time.xosc", WALK, WALK.replace('"linear"', f'"{shape}"'))
    _refused(path, f'"{shape}"', "<SpeedActionDynamics>", f"dynamicsShape {shape}", "ego", "linear")


def test_two_shapes_for_one_vru_are_refused_naming_the_second(tmp_path):
    stop = '<SpeedActionDynamics dynamicsShape="cubic" dynamicsDimension="distance" value="1.5"/>'
    path = _copy(tmp_path, DATA / "cubic_stop.xosc", stop, stop.replace('"cubic"', '"linear"'))
    line = next(n for n, text in enumerate(path.read_text().splitlines(), 1) if '"cubic"' in text)
    _refused(path, '"linear"', "dynamicsShape linear", "'vru0'", f"cubic (line {line})", "one shape")


def test_a_linear_vru_beside_a_shaped_one_is_refused(tmp_path):
    step = '<SpeedActionDynamics dynamicsShape="step" dynamicsDimension="time" value="0.0"/>\n          ' + (
        '<SpeedActionTarget><AbsoluteTargetSpeed value="1.0"/>'
    )
    path = _copy(
        tmp_path,
        DATA / "two_vrus_sinusoidal.xosc",
        step,
        step.replace('"step" dynamicsDimension="time" value="0.0"', '"linear" dynamicsDimension="time" value="1.0"'),
    )
    _refused(path, '"linear"', "dynamicsShape linear", "'vru1'", "'vru0'", "sinusoidal", "one VRU motion model")


def test_a_shaped_stop_over_a_distance_before_the_top_speed_is_refused(tmp_path):
    path = _copy(tmp_path, DATA / "cubic_stop.xosc", 'delay="2.0"', 'delay="0.5"')
    _refused(path, "<PrivateAction><LongitudinalAction>", "'vru0'", "top speed is reached")


def test_a_shaped_change_at_a_rate_of_zero_is_refused(tmp_path):
    old = 'dynamicsShape="sinusoidal" dynamicsDimension="rate" value="1.5707963267948966"'
    path = _copy(tmp_path, DATA / "sinusoidal_rate.xosc", old, old.replace("1.5707963267948966", "0.0"))
    _refused(
        path,
        'dynamicsDimension="rate" value="0.0"',
        "<SpeedActionDynamics>",
        "a sinusoidal speed change needs a rate > 0",
    )
