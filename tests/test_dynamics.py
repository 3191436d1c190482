"""Ego and VRU dynamics against analytic expectations: braking, path tracking, dt convergence, VRU profiles,
trigger timing. Expected values are computed here from first principles, never by the code under test."""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from vrusim.engine.simulate import simulate
from vrusim.scenario.loading import scenario_from_mapping

LENGTH, REAR_OVERHANG = 4.5, 0.9  # as set in conftest.minimal_scenario_dict, used by every scenario below
REAR_TO_CENTRE = LENGTH / 2 - REAR_OVERHANG
CENTRE_TO_FRONT = LENGTH / 2


class ConstantCommandPlanner:
    """Commands a fixed acceleration per variant (m/s^2) at every step, from t = 0."""

    mode_names = ("constant",)

    def __init__(self, commands):
        self.commands = np.asarray(commands, dtype=float)

    def reset(self, params) -> None:
        assert params.size == self.commands.size
        self.mode = np.zeros(params.size, dtype=np.int8)

    def act(self, observation) -> np.ndarray:
        return self.commands.copy()


class RandomCommandPlanner:
    """Random accelerations in [low, high] (seeded), redrawn every step: a stress test for the actuator."""

    def __init__(self, seed: int, low: float, high: float):
        self.rng = np.random.default_rng(seed)
        self.low, self.high = low, high

    def reset(self, params) -> None:
        self.size = params.size

    def act(self, observation) -> np.ndarray:
        return self.rng.uniform(self.low, self.high, self.size)


def braking_scenario(make_scenario, v0: float, decel: float, dt: float = 0.01):
    """Ego at v0 heading +x with no jerk limit and no lag; long route; duration covers the stop."""
    stop_time = v0 / decel
    return make_scenario(
        {
            "name": f"brake-{v0}-{decel}",
            "ego": {
                "cruise_speed_mps": v0,
                "max_decel_mps2": 12.0,
                "max_jerk_mps3": None,
                "actuator_lag_s": 0.0,
                "route": {"kind": "straight", "length_m": 2000.0},
            },
            "sim": {"dt_s": dt, "duration_s": stop_time + 10 * dt + 0.2},
        }
    )


def wrap_angle(angle: float) -> float:
    return (angle + math.pi) % (2 * math.pi) - math.pi


# ----------------------------------------------------------------------------------------------------------
# Stopping distance under constant deceleration
# ----------------------------------------------------------------------------------------------------------
BRAKE_CASES = [(v0, a) for v0 in (10.0, 15.0, 25.0) for a in (4.0, 6.0, 8.0)]


@pytest.fixture(scope="module")
def braking_batch(make_scenario):
    scenarios = [braking_scenario(make_scenario, v0, a) for v0, a in BRAKE_CASES]
    run = simulate(scenarios, planner=ConstantCommandPlanner([-a for _, a in BRAKE_CASES]), trace=True)
    return run


@pytest.mark.parametrize("index", range(len(BRAKE_CASES)), ids=[f"v0={v}-a={a}" for v, a in BRAKE_CASES])
def test_stopping_distance_matches_v2_over_2a(braking_batch, index):
    v0, a = BRAKE_CASES[index]
    trace = braking_batch.trace
    expected = v0 * v0 / (2 * a)
    x = trace["ego_x_m"][:, index]
    speed = trace["ego_speed_mps"][:, index]
    assert speed[-1] == 0.0
    travelled = x[-1] - 0.0  # ego.start (rectangle centre) is at x = 0, heading +x
    assert travelled == pytest.approx(expected, rel=0.01)
    assert trace["ego_station_m"][-1, index] == pytest.approx(expected, rel=0.01)
    # it stops at t = v0 / a (to within one step) and stays put afterwards
    t = trace["t_s"]
    first_stop = t[np.argmax(speed == 0.0)]
    dt = t[1] - t[0]
    assert v0 / a - 1e-9 <= first_stop <= v0 / a + dt + 1e-9
    assert np.all(x[speed == 0.0] == x[-1])
    # the lateral position never changes on a straight route heading +x
    assert np.all(np.abs(trace["ego_y_m"][:, index]) < 1e-9)


@settings(max_examples=30, deadline=None)
@given(v0=st.floats(2.0, 40.0), decel=st.floats(1.0, 10.0))
def test_stopping_distance_property(make_scenario, v0, decel):
    scenario = braking_scenario(make_scenario, v0, decel, dt=0.05)
    run = simulate([scenario], planner=ConstantCommandPlanner([-decel]), trace=True)
    travelled = run.trace["ego_x_m"][-1, 0]
    assert run.trace["ego_speed_mps"][-1, 0] == 0.0
    assert travelled == pytest.approx(v0 * v0 / (2 * decel), rel=0.01)


def analytic_jerk_limited_stop(v0: float, decel: float, jerk: float) -> float:
    """Stopping distance when the deceleration ramps up at `jerk` to `decel` (then constant)."""
    ramp = decel / jerk
    v_ramp = v0 - 0.5 * jerk * ramp * ramp
    if v_ramp <= 0.0:  # stops during the ramp: v0 = jerk t^2 / 2
        t = math.sqrt(2 * v0 / jerk)
        return v0 * t - jerk * t**3 / 6
    return v0 * ramp - jerk * ramp**3 / 6 + v_ramp * v_ramp / (2 * decel)


def analytic_lagged_stop(v0: float, decel: float, lag: float) -> float:
    """Stopping distance when the deceleration follows a(t) = decel (1 - exp(-t / lag)) (first-order lag)."""

    def speed(t):
        return v0 - decel * (t - lag * (1 - math.exp(-t / lag)))

    lo, hi = 0.0, v0 / decel + lag + 1.0
    for _ in range(200):  # bisection for the stop time
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if speed(mid) > 0 else (lo, mid)
    t = 0.5 * (lo + hi)
    return v0 * t - decel * (t * t / 2 - lag * t + lag * lag * (1 - math.exp(-t / lag)))


@pytest.mark.parametrize("v0", [15.0, 25.0])
@pytest.mark.parametrize(("lag", "jerk"), [(0.0, 20.0), (0.0, 5.0), (0.1, None), (0.3, None)])
def test_stopping_distance_with_jerk_limit_or_lag(make_scenario, v0, lag, jerk):
    decel = 6.0
    if jerk is not None:
        expected = analytic_jerk_limited_stop(v0, decel, jerk)
        plain_extra = expected - v0 * v0 / (2 * decel)
    else:
        expected = analytic_lagged_stop(v0, decel, lag)
        plain_extra = expected - v0 * v0 / (2 * decel)
    assert plain_extra > 0.5  # the actuator model matters at this tolerance
    scenario = make_scenario(
        {
            "ego": {
                "cruise_speed_mps": v0,
                "max_decel_mps2": decel,
                "max_jerk_mps3": jerk,
                "actuator_lag_s": lag,
                "route": {"length_m": 500.0},
            },
            "sim": {"duration_s": v0 / decel + 3.0},
        }
    )
    trace = simulate([scenario], planner=ConstantCommandPlanner([-decel]), trace=True).trace
    assert trace["ego_speed_mps"][-1, 0] == 0.0
    travelled = trace["ego_x_m"][-1, 0]
    assert travelled == pytest.approx(expected, rel=0.01)
    # the discrete actuator leads the continuous one by at most about one step of travel
    assert abs(travelled - expected) <= 1.5 * v0 * 0.01


# ----------------------------------------------------------------------------------------------------------
# No rolling backwards
# ----------------------------------------------------------------------------------------------------------
ACTUATORS = [(0.0, None), (0.3, None), (0.0, 15.0), (0.2, 25.0)]  # (lag s, jerk limit m/s^3)


@pytest.mark.parametrize("kind", ["straight", "left"])
def test_ego_never_moves_backwards(make_scenario, kind):
    scenarios = [
        make_scenario(
            {
                "name": f"random-{lag_s}-{jerk}-{v0}",
                "ego": {
                    "cruise_speed_mps": v0,
                    "actuator_lag_s": lag_s,
                    "max_jerk_mps3": jerk,
                    "max_decel_mps2": 10.0,
                    "route": {"kind": kind, "turn_at_m": 5.0, "radius_m": 12.0, "length_m": 200.0},
                },
                "sim": {"duration_s": 5.0},
            }
        )
        for lag_s, jerk in ACTUATORS
        for v0 in (0.5, 4.0, 11.0)
    ]
    # mostly braking, so every variant reaches standstill and then keeps being commanded to decelerate
    run = simulate(scenarios, planner=RandomCommandPlanner(seed=7, low=-12.0, high=3.0), trace=True)
    trace = run.trace
    speed = trace["ego_speed_mps"]
    assert np.all(speed >= 0.0)
    assert np.any(speed == 0.0)
    hx, hy = trace["ego_heading_x"], trace["ego_heading_y"]
    rear_x = trace["ego_x_m"] - REAR_TO_CENTRE * hx
    rear_y = trace["ego_y_m"] - REAR_TO_CENTRE * hy
    # displacement of the rear axle over each step, projected on the heading at the start of the step
    forward = np.diff(rear_x, axis=0) * hx[:-1] + np.diff(rear_y, axis=0) * hy[:-1]
    assert np.all(forward >= -1e-12)
    # the station is re-projected onto the sampled route every step: allow projection round-off only
    assert np.all(np.diff(trace["ego_station_m"], axis=0) >= -1e-6)
    # at standstill it does not move at all
    still = (speed[:-1] == 0.0) & (speed[1:] == 0.0)
    assert np.all(np.hypot(np.diff(rear_x, axis=0), np.diff(rear_y, axis=0))[still] < 1e-12)


# ----------------------------------------------------------------------------------------------------------
# Path tracking: rear axle against the analytic line / arc / line route
# ----------------------------------------------------------------------------------------------------------
def _point_segment_distance(px, py, ax, ay, bx, by):
    abx, aby = bx - ax, by - ay
    t = np.clip(((px - ax) * abx + (py - ay) * aby) / (abx * abx + aby * aby), 0.0, 1.0)
    return np.hypot(px - (ax + t * abx), py - (ay + t * aby))


def ideal_route_distance(px, py, start_x, start_y, heading_deg, kind, turn_at, radius, angle_deg=90.0):
    """Distance of rear-axle points to the ideal route (line, arc, line), built from the start pose.

    The route of the rear axle begins (length/2 - rear_overhang) behind the given rectangle centre.
    """
    h0 = math.radians(heading_deg)
    tx, ty = math.cos(h0), math.sin(h0)
    nx, ny = -ty, tx  # left normal
    x0, y0 = start_x - REAR_TO_CENTRE * tx, start_y - REAR_TO_CENTRE * ty
    x1, y1 = x0 + turn_at * tx, y0 + turn_at * ty
    if kind == "straight":
        return _point_segment_distance(px, py, x0 - 1e3 * tx, y0 - 1e3 * ty, x0 + 1e4 * tx, y0 + 1e4 * ty)
    sign = 1.0 if kind == "left" else -1.0
    cx, cy = x1 + sign * radius * nx, y1 + sign * radius * ny
    sweep = sign * math.radians(angle_deg)
    phi0 = math.atan2(y1 - cy, x1 - cx)
    phi1 = phi0 + sweep
    x2, y2 = cx + radius * math.cos(phi1), cy + radius * math.sin(phi1)
    h1 = h0 + sweep
    ex, ey = math.cos(h1), math.sin(h1)
    d_line1 = _point_segment_distance(px, py, x0, y0, x1, y1)
    d_line2 = _point_segment_distance(px, py, x2, y2, x2 + 1e3 * ex, y2 + 1e3 * ey)
    # arc: radial distance where the point's polar angle lies within the swept span, else the nearer end
    rel = np.arctan2(py - cy, px - cx) - phi0
    rel = (rel + math.pi) % (2 * math.pi) - math.pi  # in (-pi, pi], span is at most 90 degrees here
    within = (sign * rel >= 0.0) & (sign * rel <= abs(sweep))
    d_ends = np.minimum(np.hypot(px - x1, py - y1), np.hypot(px - x2, py - y2))
    d_arc = np.where(within, np.abs(np.hypot(px - cx, py - cy) - radius), d_ends)
    return np.minimum(np.minimum(d_line1, d_line2), d_arc)


TURN_CASES = [
    (kind, radius, speed, heading)
    for kind in ("left", "right")
    for radius in (10.0, 20.0)
    for speed in (5.0, 15.0)
    for heading in (0.0, 30.0)
]
TURN_AT, EXIT_LENGTH = 20.0, 40.0
TURN_START = (-30.0, -1.75)


@pytest.fixture(scope="module")
def turning_batch(make_scenario):
    scenarios = []
    for kind, radius, speed, heading in TURN_CASES:
        length = TURN_AT + radius * math.pi / 2 + EXIT_LENGTH
        scenarios.append(
            make_scenario(
                {
                    "name": f"turn-{kind}-{radius}-{speed}-{heading}",
                    "ego": {
                        "start": {"x_m": TURN_START[0], "y_m": TURN_START[1], "heading_deg": heading},
                        "cruise_speed_mps": speed,
                        "route": {
                            "kind": kind,
                            "turn_at_m": TURN_AT,
                            "radius_m": radius,
                            "angle_deg": 90.0,
                            "length_m": length,
                        },
                    },
                    "sim": {"duration_s": length / speed + 2.0},
                }
            )
        )
    return simulate(scenarios, trace=True)


@pytest.mark.parametrize(
    "index", range(len(TURN_CASES)), ids=[f"{k}-R{r:g}-v{v:g}-h{h:g}" for k, r, v, h in TURN_CASES]
)
def test_turn_tracking_error_and_final_heading(turning_batch, index):
    kind, radius, _speed, heading = TURN_CASES[index]
    run = turning_batch
    assert not np.isnan(run.metrics.travel_time_s[index]), "the ego must complete its route"
    steps = int(np.argmax(run.trace["t_s"] >= run.metrics.end_time_s[index] - 1e-9)) + 1
    hx = run.trace["ego_heading_x"][:steps, index]
    hy = run.trace["ego_heading_y"][:steps, index]
    rear_x = run.trace["ego_x_m"][:steps, index] - REAR_TO_CENTRE * hx
    rear_y = run.trace["ego_y_m"][:steps, index] - REAR_TO_CENTRE * hy
    error = ideal_route_distance(rear_x, rear_y, *TURN_START, heading, kind, TURN_AT, radius)
    assert error.max() < 0.1
    # the turn really happened: the rear axle went round the arc and out along the exit line
    sign = 1.0 if kind == "left" else -1.0
    final_heading = math.atan2(hy[-1], hx[-1])
    expected = math.radians(heading) + sign * math.pi / 2
    assert abs(math.degrees(wrap_angle(final_heading - expected))) < 1.0
    # position at the end: on the exit line, about EXIT_LENGTH past the arc end
    h0 = math.radians(heading)
    progress = (rear_x[-1] - (TURN_START[0] - REAR_TO_CENTRE * math.cos(h0))) * math.cos(h0) + (
        rear_y[-1] - (TURN_START[1] - REAR_TO_CENTRE * math.sin(h0))
    ) * math.sin(h0)
    assert progress == pytest.approx(TURN_AT + radius, abs=0.2)  # along the initial heading: turn_at + R


@pytest.mark.parametrize("heading", [0.0, 37.0, -120.0, 180.0])
def test_straight_route_no_lateral_error(make_scenario, heading):
    scenario = make_scenario(
        {
            "ego": {"start": {"x_m": 5.0, "y_m": -3.0, "heading_deg": heading}, "cruise_speed_mps": 12.0},
            "vrus": [
                {
                    "type": "pedestrian",
                    "start": [-400.0, 400.0],
                    "heading_deg": 0.0,
                    "trigger": {"at_time_s": 1e6},
                }
            ],
            "sim": {"duration_s": 3.0},
        }
    )
    run = simulate([scenario], trace=True)
    trace = run.trace
    hx, hy = trace["ego_heading_x"][:, 0], trace["ego_heading_y"][:, 0]
    rear_x = trace["ego_x_m"][:, 0] - REAR_TO_CENTRE * hx
    rear_y = trace["ego_y_m"][:, 0] - REAR_TO_CENTRE * hy
    error = ideal_route_distance(rear_x, rear_y, 5.0, -3.0, heading, "straight", 0.0, 1.0)
    assert error.max() < 1e-6
    h = math.radians(heading)
    assert np.allclose(hx, math.cos(h), atol=1e-9)
    assert np.allclose(hy, math.sin(h), atol=1e-9)
    # constant speed along the heading: position at time t is start + v t
    t = trace["t_s"]
    assert np.allclose(trace["ego_x_m"][:, 0], 5.0 + 12.0 * t * math.cos(h), atol=1e-6)
    assert np.allclose(trace["ego_y_m"][:, 0], -3.0 + 12.0 * t * math.sin(h), atol=1e-6)


# ----------------------------------------------------------------------------------------------------------
# dt convergence on the paper pedestrian scenario
# ----------------------------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def pedestrian_dt_runs(paper_pedestrian_dict):
    runs = {}
    for dt in (0.01, 0.005):
        variants = []
        for v2x in (False, True):
            data = copy.deepcopy(paper_pedestrian_dict)
            data["v2x"]["enabled"] = v2x
            data["sim"]["dt_s"] = dt
            variants.append(scenario_from_mapping(data))
        runs[dt] = simulate(variants).metrics
    return runs


def test_dt_convergence_without_v2x(pedestrian_dt_runs):
    coarse, fine = pedestrian_dt_runs[0.01], pedestrian_dt_runs[0.005]
    assert coarse.collided[0] == fine.collided[0]
    if coarse.collided[0]:
        assert abs(coarse.impact_ego_speed_mps[0] - fine.impact_ego_speed_mps[0]) <= 0.2
        assert abs(coarse.contact_time_s[0] - fine.contact_time_s[0]) <= 0.05


def test_dt_convergence_with_v2x(pedestrian_dt_runs):
    for dt, metrics in pedestrian_dt_runs.items():
        assert not metrics.collided[1], f"V2X on, dt={dt}: the ego must avoid the pedestrian"
        assert np.isnan(metrics.impact_ego_speed_mps[1])
    assert abs(pedestrian_dt_runs[0.01].min_clearance_m[1] - pedestrian_dt_runs[0.005].min_clearance_m[1]) < 0.2


# ----------------------------------------------------------------------------------------------------------
# VRU motion profile
# ----------------------------------------------------------------------------------------------------------
def analytic_vru_distance(t, start, top_speed, accel):
    """Distance along the path from rest: constant accel to top speed, then constant speed."""
    tau = np.maximum(np.asarray(t) - start, 0.0)
    t_top = top_speed / accel
    return np.where(
        tau <= t_top, 0.5 * accel * tau * tau, top_speed * top_speed / (2 * accel) + top_speed * (tau - t_top)
    )


# top speed / accel chosen so that the time to top speed is a multiple of dt (the profile is then exact)
VRU_CASES = [
    ("pedestrian", 1.8, 1.0, 0.5, 90.0),
    ("pedestrian", 1.5, 2.0, 0.3, -135.0),
    ("cyclist", 5.0, 2.5, 1.0, 10.0),
    ("motorcyclist", 12.0, 4.0, 0.0, 180.0),
]


@pytest.fixture(scope="module")
def vru_profile_run(make_scenario):
    vrus = [
        {
            "type": kind,
            "start": {"x_m": 40.0 + 30.0 * k, "y_m": 40.0},
            "heading_deg": heading,
            "top_speed_mps": top,
            "max_accel_mps2": accel,
            "speed_time_constant_s": 0.0,
            "trigger": {"at_time_s": trigger},
        }
        for k, (kind, top, accel, trigger, heading) in enumerate(VRU_CASES)
    ]
    scenario = make_scenario({"ego": {"cruise_speed_mps": 0.0}, "vrus": vrus, "sim": {"duration_s": 6.0}})
    return simulate([scenario], trace=True)


@pytest.mark.parametrize("k", range(len(VRU_CASES)), ids=[f"{c[0]}-{c[1]}" for c in VRU_CASES])
def test_vru_accelerates_then_holds_top_speed(vru_profile_run, k):
    _kind, top, accel, trigger, heading = VRU_CASES[k]
    trace = vru_profile_run.trace
    t = trace["t_s"]
    x0, y0 = 40.0 + 30.0 * k, 40.0
    h = math.radians(heading)
    along = (trace["vru_x_m"][:, 0, k] - x0) * math.cos(h) + (trace["vru_y_m"][:, 0, k] - y0) * math.sin(h)
    across = -(trace["vru_x_m"][:, 0, k] - x0) * math.sin(h) + (trace["vru_y_m"][:, 0, k] - y0) * math.cos(h)
    np.testing.assert_allclose(along, analytic_vru_distance(t, trigger, top, accel), rtol=0, atol=1e-6)
    np.testing.assert_allclose(across, 0.0, atol=1e-9)
    speed = trace["vru_speed_mps"][:, 0, k]
    at_top = t >= trigger + top / accel + 1e-6
    assert at_top.sum() > 10
    np.testing.assert_allclose(speed[at_top], top, rtol=0, atol=1e-12)
    assert np.all(speed <= top + 1e-12)
    assert np.all(speed[t <= trigger + 1e-9] == 0.0)


@pytest.mark.parametrize("trigger", [0.503, 1.0, 2.2345])
def test_vru_does_not_move_before_time_trigger(make_scenario, trigger):
    dt = 0.01
    scenario = make_scenario(
        {
            "ego": {"cruise_speed_mps": 0.0},
            "vrus": [
                {
                    "type": "cyclist",
                    "start": [30.0, 20.0],
                    "heading_deg": 45.0,
                    "trigger": {"at_time_s": trigger},
                }
            ],
            "sim": {"duration_s": 4.0, "dt_s": dt},
        }
    )
    trace = simulate([scenario], trace=True).trace
    t = trace["t_s"]
    moved = np.hypot(trace["vru_x_m"][:, 0, 0] - 30.0, trace["vru_y_m"][:, 0, 0] - 20.0) > 0.0
    assert not moved[t <= trigger + 1e-9].any()
    # it starts within one step of the trigger time: the step beginning in [trigger, trigger + dt) moves it
    first_moved = t[np.argmax(moved)]
    assert trigger < first_moved <= trigger + 2 * dt + 1e-9


# ----------------------------------------------------------------------------------------------------------
# Distance and time-to-arrival triggers
# ----------------------------------------------------------------------------------------------------------
def _rotate(x, y, angle_deg):
    a = math.radians(angle_deg)
    return x * math.cos(a) - y * math.sin(a), x * math.sin(a) + y * math.cos(a)


TRIGGER_CASES = [
    # (condition, value, point in the ego frame, ego heading in degrees, ego speed)
    ("ego_distance_m", 20.0, (60.0, -3.0), 0.0, 10.0),
    ("ego_distance_m", 12.5, (45.0, 0.0), 90.0, 8.0),
    ("ego_distance_m", 35.0, (70.0, 6.0), -150.0, 14.0),
    ("ego_time_to_arrival_s", 2.5, (60.0, -3.0), 0.0, 10.0),
    ("ego_time_to_arrival_s", 4.0, (80.0, 2.0), 45.0, 15.0),
]


@pytest.mark.parametrize("case", TRIGGER_CASES, ids=lambda c: f"{c[0]}={c[1]}@{c[3]:g}deg")
def test_distance_and_arrival_triggers_fire_on_time(make_scenario, case):
    condition, value, (px_local, py_local), heading, speed = case
    dt = 0.01
    start = (3.0, -4.0)
    # the VRU itself stands well off the road (ego frame: 20 m ahead of the point, 8 m to the right)
    vx_local, vy_local = px_local + 20.0, -8.0
    point = tuple(s + r for s, r in zip(start, _rotate(px_local, py_local, heading), strict=True))
    vru_start = tuple(s + r for s, r in zip(start, _rotate(vx_local, vy_local, heading), strict=True))
    # analytic: the front bumper is at (LENGTH/2 + v t) along the heading; the trigger distance is Euclidean
    reach = value if condition == "ego_distance_m" else value * speed
    ahead = px_local - CENTRE_TO_FRONT - math.sqrt(reach * reach - py_local * py_local)
    expected = ahead / speed
    assert 0.5 < expected < 6.0  # the cases are designed to fire mid-run
    scenario = make_scenario(
        {
            "ego": {
                "start": {"x_m": start[0], "y_m": start[1], "heading_deg": heading},
                "cruise_speed_mps": speed,
            },
            "vrus": [
                {
                    "type": "pedestrian",
                    "start": list(vru_start),
                    "heading_deg": heading - 90.0,
                    "trigger": {condition: value, "point": list(point)},
                }
            ],
            "sim": {"duration_s": expected + 0.3, "dt_s": dt},
        }
    )
    trace = simulate([scenario], trace=True).trace
    t = trace["t_s"]
    moving = trace["vru_speed_mps"][:, 0, 0] > 0.0
    assert moving.any()
    fired_at = t[np.argmax(moving)] - dt  # the step that starts at the firing time moves the VRU
    assert expected - 1e-9 <= fired_at <= expected + dt + 1e-9
