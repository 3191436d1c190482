"""VRU speed profiles beyond 'from rest to top speed': initial speed, braking phase, route-distance trigger,
stationary targets; and the engine's record of a planner's forward-collision warning."""

from __future__ import annotations

import math

import numpy as np
import pytest

from vrusim.engine.simulate import simulate
from vrusim.planners.base import HoldSpeedPlanner


def _far_vru(**fields) -> dict:
    vru = {"type": "motorcyclist", "start": [60.0, 40.0], "heading_deg": 0.0, "max_accel_mps2": 5.0}
    vru.update(fields)
    return vru


def test_initial_speed_is_held_until_the_trigger_then_brakes_to_a_stop(make_scenario):
    """A target moving at 10 m/s from t = 0, triggered at 1 s, brakes 0.5 s later at 4 m/s^2 to a standstill."""
    v0, decel, trigger, delay = 10.0, 4.0, 1.0, 0.5
    vru = _far_vru(
        top_speed_mps=v0,
        initial_speed_mps=v0,
        trigger={"at_time_s": trigger},
        brake={"after_trigger_s": delay, "decel_mps2": decel},
    )
    scenario = make_scenario({"ego": {"cruise_speed_mps": 0.0}, "vrus": [vru], "sim": {"duration_s": 6.0}})
    trace = simulate([scenario], trace=True).trace
    t, x, speed = trace["t_s"], trace["vru_x_m"][:, 0, 0] - 60.0, trace["vru_speed_mps"][:, 0, 0]
    brake_start = trigger + delay
    cruising = t <= brake_start + 1e-9
    np.testing.assert_allclose(speed[cruising], v0, atol=1e-12)
    np.testing.assert_allclose(x[cruising], v0 * t[cruising], atol=1e-9)
    # stopping distance v0^2 / (2 a) after the braking onset, within 1 %
    stop_distance = x[-1] - v0 * brake_start
    assert stop_distance == pytest.approx(v0 * v0 / (2 * decel), rel=0.01)
    assert speed[-1] == 0.0
    stopped_at = t[np.argmax(speed == 0.0)]
    assert stopped_at == pytest.approx(brake_start + v0 / decel, abs=0.011)


def test_initial_speed_before_a_late_trigger_keeps_moving(make_scenario):
    """A moving target whose trigger has not fired keeps its initial speed (it does not stop or accelerate)."""
    vru = _far_vru(top_speed_mps=20.0, initial_speed_mps=5.0, trigger={"at_time_s": 100.0})
    scenario = make_scenario({"ego": {"cruise_speed_mps": 0.0}, "vrus": [vru], "sim": {"duration_s": 2.0}})
    trace = simulate([scenario], trace=True).trace
    np.testing.assert_allclose(trace["vru_speed_mps"][:, 0, 0], 5.0, atol=1e-12)
    np.testing.assert_allclose(trace["vru_x_m"][-1, 0, 0] - 60.0, 5.0 * trace["t_s"][-1], atol=1e-9)


@pytest.mark.parametrize("route_m", [0.0, 7.3, 25.0])
def test_route_trigger_fires_at_the_step_the_ego_has_travelled_the_distance(make_scenario, route_m):
    """Ego at 10 m/s: a trigger at route distance d fires at the first step start with station >= d."""
    vru = {"type": "pedestrian", "start": [60.0, 40.0], "heading_deg": 90.0, "top_speed_mps": 1.0,
           "max_accel_mps2": 100.0, "trigger": {"ego_route_m": route_m}}  # fmt: skip
    scenario = make_scenario({"vrus": [vru], "sim": {"duration_s": 4.0}})
    trace = simulate([scenario], trace=True).trace
    moved = trace["vru_y_m"][:, 0, 0] > 40.0
    first_row = int(np.argmax(moved))
    # row i holds the state at (i + 1) dt; the VRU moves in the step starting at the trigger time
    fired_at = trace["t_s"][first_row] - 0.01
    expected = math.ceil(route_m / 10.0 / 0.01 - 1e-9) * 0.01
    assert fired_at == pytest.approx(expected, abs=1e-9)


def test_stationary_target_never_moves(make_scenario):
    vru = _far_vru(top_speed_mps=0.0, trigger={"at_time_s": 0.0})
    scenario = make_scenario({"ego": {"cruise_speed_mps": 0.0}, "vrus": [vru], "sim": {"duration_s": 1.0}})
    trace = simulate([scenario], trace=True).trace
    assert np.all(trace["vru_x_m"][:, 0, 0] == 60.0)
    assert np.all(trace["vru_speed_mps"] == 0.0)


class _WarnAtTime(HoldSpeedPlanner):
    """Holds speed; raises its warning flag from a set time on."""

    def __init__(self, at_s: float):
        self.at_s = at_s

    def reset(self, params) -> None:
        super().reset(params)
        self.warning = np.zeros(params.size, dtype=bool)

    def act(self, observation):
        self.warning = np.full(self.mode.shape, observation.t_s >= self.at_s - 1e-9)
        return super().act(observation)


def test_first_warning_time_and_its_ttc_are_recorded(make_scenario):
    """Ego at 10 m/s towards a standing pedestrian 30 m ahead of its front: TTC at t is (30 - r - 10 t) / 10."""
    front_x = 2.25  # ego centre at 0, length 4.5
    radius = 0.5
    vru = {"type": "pedestrian", "start": [front_x + 30.0 + radius, 0.0], "heading_deg": 90.0,
           "radius_m": radius, "top_speed_mps": 0.0}  # fmt: skip
    scenario = make_scenario({"vrus": [vru], "sim": {"duration_s": 4.0}})
    run = simulate([scenario], planner=_WarnAtTime(1.0))
    assert run.metrics.first_warning_s[0] == pytest.approx(1.0)
    assert run.metrics.warning_ttc_s[0] == pytest.approx((30.0 - 10.0 * 1.0) / 10.0, abs=1e-6)
    silent = simulate([scenario], planner=HoldSpeedPlanner())
    assert math.isnan(silent.metrics.first_warning_s[0])


def test_route_trigger_starts_the_profile_at_the_exact_crossing_instant(make_scenario):
    """The ego (10 m/s) passes 7.345 m at t = 0.7345 s, inside a step: the VRU's profile starts there, not at 0.74 s."""
    top, accel, crossing = 2.0, 1.0, 0.7345
    vru = {"type": "pedestrian", "start": [60.0, 40.0], "heading_deg": 90.0, "top_speed_mps": top,
           "max_accel_mps2": accel, "trigger": {"ego_route_m": 10.0 * crossing}}  # fmt: skip
    scenario = make_scenario({"vrus": [vru], "sim": {"duration_s": 5.0}})
    trace = simulate([scenario], trace=True).trace
    tau = np.maximum(trace["t_s"] - crossing, 0.0)
    t_top = top / accel
    expected = np.where(tau <= t_top, 0.5 * accel * tau**2, top * top / (2 * accel) + top * (tau - t_top))
    np.testing.assert_allclose(trace["vru_y_m"][:, 0, 0] - 40.0, expected, atol=2e-4)
