"""The shaped VRU motion models `cubic` and `sinusoidal` (vrusim.sim.vru.shaped): speed changes along
v0 + (v1 - v0) h(s) over T = |v1 - v0| / max_accel_mps2, checked against the closed-form speed and distance, the
peak acceleration, the triggers and braking of `point_mass`, and a hypothesis test over v0, v1 and T."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from vrusim.engine.simulate import simulate
from vrusim.errors import UserInputError
from vrusim.sim.params import pack
from vrusim.sim.vru.shaped import (
    CUBIC,
    PEAK_TO_MEAN_RATE,
    SHAPE_CODES,
    SINUSOIDAL,
    shape_fraction,
    shape_integral,
)
from vrusim.sim.vru.shaped_motion import shaped_profile

SHAPES = (CUBIC, SINUSOIDAL)
Y0_M = -20.0
"""Every test VRU starts at (50, -20) and walks along +y, far off the ego's road."""


def _vru(motion: str, **fields) -> dict:
    base = {"type": "pedestrian", "start": {"x_m": 50.0, "y_m": Y0_M}, "heading_deg": 90.0, "motion": motion}
    return base | fields


def _traces(make_scenario, vrus: list[dict], duration_s: float = 8.0) -> dict[str, np.ndarray]:
    """Trace of one batch: one variant per VRU mapping (planner none, ego at 10 m/s along +x)."""
    scenarios = [make_scenario({"vrus": [vru], "sim": {"duration_s": duration_s}}) for vru in vrus]
    return simulate(scenarios, trace=True).trace


def _at(trace: dict[str, np.ndarray], key: str, t_s: float, variant: int = 0) -> float:
    return float(np.interp(t_s, trace["t_s"], trace[key][:, variant, 0]))


def _walked(trace: dict[str, np.ndarray], t_s: float, variant: int = 0) -> float:
    return _at(trace, "vru_y_m", t_s, variant) - Y0_M


def _ramp(shape: str, v0: float, v1: float, duration_s: float, u_s: float) -> tuple[float, float]:
    """Hand-derived (speed, distance) u_s after the start of a change v0 -> v1 over duration_s (held after)."""
    if u_s >= duration_s:
        return v1, (v0 + v1) / 2 * duration_s + v1 * (u_s - duration_s)
    s = u_s / duration_s
    return v0 + (v1 - v0) * shape_fraction(shape, s), v0 * u_s + (v1 - v0) * duration_s * shape_integral(shape, s)


@pytest.mark.parametrize("shape", SHAPES)
def test_a_shaped_start_follows_its_shape_and_covers_the_mean_speed_times_its_duration(make_scenario, shape):
    # at t = 1 s from 0.5 to 2.5 m/s at a mean rate of 1 m/s^2: T = 2 s
    trace = _traces(make_scenario, [_vru(shape, initial_speed_mps=0.5, top_speed_mps=2.5, max_accel_mps2=1.0,
                                         trigger={"at_time_s": 1.0})])  # fmt: skip
    assert abs(_walked(trace, 1.0) - 0.5) < 1e-9  # the initial speed is held until the trigger
    for t_s in np.arange(1.0, 6.0, 0.13):
        speed, distance = _ramp(shape, 0.5, 2.5, 2.0, t_s - 1.0)
        assert abs(_at(trace, "vru_speed_mps", t_s) - speed) < 1e-3  # between steps: linear interpolation
        assert abs(_walked(trace, t_s) - 0.5 - distance) < 1e-4
    assert abs(_walked(trace, 3.0) - 0.5 - (0.5 + 2.5) / 2 * 2.0) < 1e-9
    assert _at(trace, "vru_speed_mps", 3.0) == pytest.approx(2.5, abs=1e-12)


@pytest.mark.parametrize("shape", SHAPES)
def test_the_peak_acceleration_is_the_shapes_factor_times_the_mean_rate(make_scenario, shape):
    trace = _traces(make_scenario, [_vru(shape, top_speed_mps=2.0, max_accel_mps2=0.8, trigger={"at_time_s": 0.5})])
    accel = np.diff(trace["vru_speed_mps"][:, 0, 0]) / 0.01
    factor = {CUBIC: 1.5, SINUSOIDAL: math.pi / 2}[shape]
    assert PEAK_TO_MEAN_RATE[shape] == factor
    assert abs(accel.max() - factor * 2.0 / 2.5) < 1e-3  # T = 2 / 0.8 = 2.5 s; peak at T / 2
    assert abs(trace["t_s"][accel.argmax()] + 0.005 - (0.5 + 1.25)) < 0.011
    code = SHAPE_CODES[shape]
    _, peak, _ = shaped_profile(code, 0.0, 2.0, 0.8, math.inf, 0.0, 1.25)
    assert peak == pytest.approx(factor * 0.8, rel=1e-12)
    assert shaped_profile(code, 0.0, 2.0, 0.8, math.inf, 0.0, 0.0)[1] == 0.0  # smooth start
    assert abs(shaped_profile(code, 0.0, 2.0, 0.8, math.inf, 0.0, 2.5 - 1e-12)[1]) < 1e-9  # and end


@pytest.mark.parametrize("shape", SHAPES)
def test_a_brake_during_the_start_follows_the_shape_from_the_speed_then(make_scenario, shape):
    # at t = 1 s from 0 to 3 m/s at 1 m/s^2 (T = 3 s); 1.5 s after the trigger to 0 at a mean 2 m/s^2
    vru = _vru(shape, top_speed_mps=3.0, max_accel_mps2=1.0, trigger={"at_time_s": 1.0},
               brake={"after_trigger_s": 1.5, "decel_mps2": 2.0})  # fmt: skip
    trace = _traces(make_scenario, [vru])
    speed_b, walked_b = _ramp(shape, 0.0, 3.0, 3.0, 1.5)
    assert speed_b == pytest.approx(1.5)  # both shapes are half-way at half-time
    stop_s = speed_b / 2.0
    assert abs(_walked(trace, 2.5) - walked_b) < 1e-9
    for u_s in (0.1, 0.37, 0.6, stop_s, 2.0):
        speed, distance = _ramp(shape, speed_b, 0.0, stop_s, u_s)
        assert abs(_at(trace, "vru_speed_mps", 2.5 + u_s) - speed) < 1e-3
        assert abs(_walked(trace, 2.5 + u_s) - walked_b - distance) < 1e-4
    assert abs(_walked(trace, 6.0) - walked_b - speed_b * stop_s / 2) < 1e-9
    assert _at(trace, "vru_speed_mps", 6.0) == 0.0


@pytest.mark.parametrize(
    "trigger",
    [
        {"at_time_s": 1.234},
        {"ego_route_m": 17.3},
        {"ego_distance_m": 12.0, "point": {"x_m": 40.0, "y_m": 0.0}},
        {"ego_time_to_arrival_s": 1.1, "point": {"x_m": 45.0, "y_m": 0.0}},
        {"ego_speed_above_mps": 100.0},
        {"ego_speed_below_mps": 100.0},
    ],
    ids=["time", "route", "distance", "time to arrival", "speed above (never)", "speed below (at once)"],
)
def test_triggers_fire_as_for_the_point_mass(make_scenario, trigger):
    """After a change the shaped and linear ramps have covered the same distance, so started at the same instant
    they are at the same place; before the trigger all hold the initial speed (one model per batch: three runs)."""
    fields = {"initial_speed_mps": 0.3, "top_speed_mps": 1.8, "max_accel_mps2": 1.5, "trigger": trigger}
    traces = [_traces(make_scenario, [_vru(m, **fields)], 6.0) for m in ("point_mass", CUBIC, SINUSOIDAL)]
    if "ego_speed_below_mps" not in trigger:  # met at once: no wait
        assert all(abs(_walked(trace, 0.5) - 0.15) < 1e-9 for trace in traces)
    linear, cubic, sine = (_walked(trace, 6.0) for trace in traces)
    if "ego_speed_above_mps" in trigger:  # never met: all hold the initial speed
        assert all(abs(_walked(trace, 6.0) - 0.3 * 6.0) < 1e-9 for trace in traces)
        return
    assert linear > 2.0 and abs(cubic - linear) < 1e-3 and abs(sine - linear) < 1e-3


def test_a_speed_time_constant_is_refused(make_scenario):
    scenario = make_scenario({"vrus": [_vru(CUBIC, speed_time_constant_s=0.5)]})
    with pytest.raises(UserInputError, match=r"speed_time_constant_s: VRU motion model 'cubic' shapes"):
        pack([scenario])


def test_the_models_are_registered_and_cannot_share_a_batch_with_the_point_mass(make_scenario):
    assert pack([make_scenario({"vrus": [_vru(SINUSOIDAL)]})]).vru_motion == SINUSOIDAL
    mixed = [make_scenario({"vrus": [_vru(CUBIC)]}), make_scenario()]
    with pytest.raises(UserInputError, match="one batch moves all its VRUs by one motion model"):
        pack(mixed)


@settings(max_examples=200, deadline=None)
@given(
    shape=st.sampled_from(SHAPES),
    v0=st.floats(0.0, 12.0),
    v1=st.floats(0.0, 12.0),
    duration=st.floats(0.05, 20.0),
    fraction=st.floats(0.0, 1.0),
)
def test_the_profile_matches_its_closed_form(shape, v0, v1, duration, fraction):
    """Any v0, v1, T: speed and distance as hand-derived, v1 reached after T having covered (v0 + v1) T / 2, the
    peak acceleration at T / 2 the shape's factor times the mean rate."""
    if abs(v1 - v0) < 1e-3:
        return
    code, rate = SHAPE_CODES[shape], abs(v1 - v0) / duration
    duration = abs(v1 - v0) / rate  # the duration the model derives from the rate
    speed, _, distance = shaped_profile(code, v0, v1, rate, math.inf, 0.0, fraction * duration)
    expected_speed, expected_distance = _ramp(shape, v0, v1, duration, fraction * duration)
    assert speed == pytest.approx(expected_speed, abs=1e-9)
    assert distance == pytest.approx(expected_distance, abs=1e-9 * (1 + expected_distance))
    speed, accel, distance = shaped_profile(code, v0, v1, rate, math.inf, 0.0, duration)
    assert speed == v1 and accel == 0.0
    assert distance == pytest.approx((v0 + v1) / 2 * duration, rel=1e-12)
    _, peak, _ = shaped_profile(code, v0, v1, rate, math.inf, 0.0, duration / 2)
    assert peak == pytest.approx(math.copysign(PEAK_TO_MEAN_RATE[shape] * rate, v1 - v0), rel=1e-9)


def test_stepped_ramps_match_the_closed_form_in_one_batch(make_scenario):
    """A grid of v0, v1 and T stepped by the engine (dt 0.01 s): the distance at T and at 0.37 T as hand-derived."""
    cases = [(v0, v1, duration) for v0 in (0.0, 1.3) for v1 in (0.0, 2.2, 6.0) for duration in (0.3, 1.7) if v0 != v1]
    for shape in SHAPES:
        vrus = [_vru(shape, initial_speed_mps=v0, top_speed_mps=v1, max_accel_mps2=abs(v1 - v0) / duration,
                     trigger={"at_time_s": 0.25}) for v0, v1, duration in cases]  # fmt: skip
        trace = _traces(make_scenario, vrus, 3.0)
        for variant, (v0, v1, duration) in enumerate(cases):
            for u_s in (0.37 * duration, duration):
                t_s = 0.25 + u_s
                expected = 0.25 * v0 + _ramp(shape, v0, v1, duration, u_s)[1]
                assert abs(_walked(trace, t_s, variant) - expected) < 2e-3, (shape, v0, v1, duration, u_s)
