"""Low-speed situations (Euro NCAP LSC26): the driver schedule, the opening door, side-impact location, and the
reference functions acpe / reverse_aeb / dow, against hand computation and end to end."""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from vrusim.engine.simulate import simulate
from vrusim.errors import UserInputError
from vrusim.metrics.summary import summary_rows
from vrusim.scenario.loading import scenario_from_mapping
from vrusim.sim.door import door_outer_corner, pack_door

LENGTH, WIDTH, WHEELBASE, REAR_OVERHANG = 4.5, 1.8, 2.7, 0.9
DT = 0.01


def scenario(ego: dict, vrus: list[dict], planner: str = "none", params: dict | None = None, **sim) -> object:
    base_ego = {
        "start": {"x_m": 0.0, "y_m": 0.0, "heading_deg": 0.0},
        "cruise_speed_mps": 0.0,
        "route": {"kind": "straight", "length_m": 100.0},
        "length_m": LENGTH,
        "width_m": WIDTH,
        "wheelbase_m": WHEELBASE,
        "rear_overhang_m": REAR_OVERHANG,
        "max_accel_mps2": 5.0,
        "max_decel_mps2": 10.0,
    }
    base_ego.update(ego)
    data = {
        "name": "lsc",
        "ego": base_ego,
        "planner": {"name": planner, "params": params or {}},
        "sensor": {"fov_deg": 360.0, "range_m": 30.0},
        "vrus": vrus,
        "sim": {"dt_s": DT, "duration_s": 8.0, **sim},
    }
    return scenario_from_mapping(data, "test")


FAR = {"type": "pedestrian", "start": [500.0, 500.0], "heading_deg": 90.0, "top_speed_mps": 0.0}


def row(s) -> dict:
    return summary_rows(simulate([s]))[0]


# ------------------------------------------------------------------------------------------------ the driver


@settings(max_examples=15, deadline=None)
@given(
    start=st.floats(0.0, 2.0),
    accel=st.floats(0.5, 4.0),
    target=st.floats(0.5, 6.0),
)
def test_start_from_standstill_follows_the_closed_form(start, accel, target):
    """SfS: held at rest until `start`, then a constant `accel` up to `target`: v(t) = min(a (t - t0), v*)."""
    driver = {"phases": [{"at_time_s": start, "target_speed_mps": target, "accel_mps2": accel}]}
    s = scenario({"initial_speed_mps": 0.0, "driver": driver}, [FAR], duration_s=6.0)
    trace = simulate([s], trace=True).trace
    t, v, station = trace["t_s"], trace["ego_speed_mps"][:, 0], trace["ego_station_m"][:, 0]
    t0 = math.ceil(start / DT - 1e-9) * DT  # the phase starts on the first step at or after `start`
    tau = np.maximum(t - t0, 0.0)
    expected_v = np.minimum(accel * tau, target)
    assert np.allclose(v, expected_v, atol=1e-9 + accel * DT)
    ramp = target / accel
    expected_s = np.where(tau < ramp, 0.5 * accel * tau**2, 0.5 * accel * ramp**2 + target * (tau - ramp))
    assert np.allclose(station, expected_s, atol=accel * DT * DT)  # the step that reaches v*: within a*dt^2
    assert np.all(v[t <= start - DT] == 0.0)


def test_a_driver_holding_the_start_speed_is_bit_identical_to_no_driver():
    """The request of a driver keeping the start speed is 0: the `none` and `aeb` runs equal those without one."""
    child = {"type": "pedestrian", "start": [20.0, 0.0], "heading_deg": 90.0, "top_speed_mps": 0.0}
    driver = {"phases": [{"at_time_s": 0.0, "target_speed_mps": 5.0, "accel_mps2": 2.0}]}
    for planner in ("none", "aeb"):
        plain = scenario({"cruise_speed_mps": 5.0}, [child], planner)
        driven = scenario({"cruise_speed_mps": 5.0, "driver": driver}, [child], planner)
        a, b = simulate([plain], trace=True), simulate([driven], trace=True)
        for name in ("ego_x_m", "ego_speed_mps", "ego_command_mps2"):
            assert np.array_equal(a.trace[name], b.trace[name]), (planner, name)
        assert np.array_equal(a.metrics.values, b.metrics.values, equal_nan=True), planner


def test_phases_start_on_route_distance_in_order():
    """Creep, then the accelerator once the rear axle has travelled 1.0 m (CPMFC's d)."""
    driver = {
        "creep_speed_mps": 1.5,
        "phases": [
            {"at_time_s": 0.0, "target_speed_mps": 1.5, "accel_mps2": 1.0, "accelerator": False},
            {"ego_route_m": 1.0, "target_speed_mps": 6.0, "accel_mps2": 4.0},
        ],
    }
    trace = simulate([scenario({"initial_speed_mps": 0.0, "driver": driver}, [FAR])], trace=True).trace
    station, request = trace["ego_station_m"][:, 0], trace["driver_accel_mps2"][:, 0]
    # row i: request decided at the start of step i from station[i - 1]
    switch = int(np.argmax(request > 1.01))
    assert station[switch - 1] >= 1.0 - 1e-9 > station[switch - 2]
    assert request[switch] == pytest.approx(4.0)


def test_bad_driver_and_door_input_names_the_field():
    with pytest.raises(UserInputError, match="phases"):
        phases = [{"at_time_s": t, "target_speed_mps": 1, "accel_mps2": 1} for t in (2.0, 1.0)]
        scenario({"driver": {"phases": phases}}, [FAR])
    with pytest.raises(UserInputError, match="exactly one"):
        scenario({"driver": {"phases": [{"target_speed_mps": 1, "accel_mps2": 1}]}}, [FAR])
    with pytest.raises(UserInputError, match="door"):
        scenario({"door": {"hinge_from_front_m": 4.0, "length_m": 1.0, "trigger": {"at_time_s": 0}}}, [FAR])
    with pytest.raises(UserInputError, match=r"ego\.door\.trigger\.vru"):
        scenario({"door": {"trigger": {"vru_distance_m": 5.0, "vru": 3}}}, [FAR])


# ------------------------------------------------------------------------------------------------ the door


@settings(max_examples=25, deadline=None)
@given(angle_deg=st.floats(0.0, 90.0), side=st.sampled_from(["left", "right"]), reverse=st.booleans())
def test_door_outer_corner_matches_hand_computation(angle_deg, side, reverse):
    """Outer rear corner, body frame: x = L/2 - h - l cos(a) + t sin(a), y = s (W/2 + l sin(a) + t cos(a));
    mirrored (x, y -> -x, -y) in the simulated frame of a reversing ego."""
    s = scenario({"reverse": reverse, "door": {"side": side, "trigger": {"at_time_s": 0.0}}}, [FAR])
    door = s.ego.door
    a = math.radians(angle_deg)
    sign = 1.0 if side == "left" else -1.0
    x = LENGTH / 2 - door.hinge_from_front_m - door.length_m * math.cos(a) + door.thickness_m * math.sin(a)
    y = sign * (WIDTH / 2 + door.length_m * math.sin(a) + door.thickness_m * math.cos(a))
    m = -1.0 if reverse else 1.0
    got_x, got_y = door_outer_corner(pack_door([s.ego]), np.array([a]))
    assert got_x[0] == pytest.approx(m * x, abs=1e-12)
    assert got_y[0] == pytest.approx(m * y, abs=1e-12)


def test_door_opens_at_its_rate_after_the_trigger_and_delay():
    door = {"trigger": {"at_time_s": 0.5}, "delay_s": 0.25, "opening_rate_deg_ps": 40.0, "max_angle_deg": 30.0}
    trace = simulate([scenario({"door": door}, [FAR], duration_s=3.0)], trace=True).trace
    t, angle = trace["t_s"], np.degrees(trace["door_angle_rad"][:, 0])
    assert np.allclose(angle, np.clip(40.0 * (t - 0.75), 0.0, 30.0), atol=1e-9)


CYCLIST_SPEED = 15 / 3.6


def dooring(planner: str, distance_m: float = 8.0, **params):
    """CBDA: parked ego facing +x; a cyclist from behind at 15 km/h, its centre 1 m + radius outside the left
    side; the driver's door is operated at `distance_m` (LSC26 §3.2.3: 8 m at 15 km/h)."""
    radius = 0.3
    cyclist = {
        "type": "cyclist", "start": [-25.0, WIDTH / 2 + 1.0], "heading_deg": 0.0, "top_speed_mps": CYCLIST_SPEED,
        "initial_speed_mps": CYCLIST_SPEED, "radius_m": radius,
    }  # fmt: skip
    door = {"trigger": {"vru_distance_m": distance_m}, "max_angle_deg": 70.0, "opening_rate_deg_ps": 90.0}
    return scenario({"door": door}, [cyclist], planner, params, duration_s=10.0)


def test_with_no_function_the_cyclist_hits_the_opened_door():
    result = row(dooring("none"))
    assert result["collided"] and result["door_collision"]
    assert result["impact_body_side"] == "left"


def test_dow_holds_the_door_and_releases_it_after_the_cyclist_passed():
    s = dooring("dow")
    run = simulate([s], trace=True)
    result = summary_rows(run)[0]
    assert not result["collided"]
    assert result["first_warning_s"] is not None
    # retention starts at TTC_door >= 1.70 s (LSC26 §5.2.3): the door's rear edge is 1.3 + 1.1 m behind the front
    door_rear_x = LENGTH / 2 - 2.4
    start = result["first_mode_s"]["retention"]
    cyclist_front = -25.0 + CYCLIST_SPEED * start + 0.3
    assert (door_rear_x - cyclist_front) / CYCLIST_SPEED >= 1.7
    ends = [x["t_s"] for x in result["transitions"] if x["to"] == "idle"]
    assert ends, "retention must end once the cyclist has passed"
    front_at_end = -25.0 + CYCLIST_SPEED * ends[0] + 0.3
    assert (door_rear_x - front_at_end) / CYCLIST_SPEED <= -0.4
    assert run.trace["door_angle_rad"][-1, 0] > 0.0  # the door opened after the release


def test_dow_without_retention_only_warns():
    result = row(dooring("dow", retention=False))
    assert result["collided"] and result["door_collision"] and result["first_warning_s"] is not None


def test_dow_needs_a_door():
    with pytest.raises(UserInputError, match=r"ego\.door"):
        simulate([scenario({}, [FAR], "dow")])


def test_a_plugin_class_path_runs_like_the_builtin():
    a = row(dooring("dow"))
    b = row(dooring("vrusim.planners.dow:DowPlanner"))
    assert {k: v for k, v in a.items() if k != "planner"} == {k: v for k, v in b.items() if k != "planner"}


# ------------------------------------------------------------------------------------------------ impact location


@settings(max_examples=20, deadline=None)
@given(fraction=st.floats(0.05, 0.95), reverse=st.booleans(), from_left=st.booleans())
def test_side_impact_location_is_the_fraction_of_length(fraction, reverse, from_left):
    """CMCscp: a motorcyclist on a perpendicular path hits the side of an ego driving at 5 m/s; its centre at the
    contact is `fraction` of the body length from the rear (hand-computed synchronisation)."""
    speed, moto, radius = 5.0, 8.0, 0.4
    # ego centre x(t) = x0 + m v t, m = -1 when reversing (it drives toward -x facing +x)
    m = -1.0 if reverse else 1.0
    side = 1.0 if from_left else -1.0
    y0 = side * (WIDTH / 2 + radius + moto * 1.0)  # contact after 1.0 s
    x_hit = m * speed * 1.0 + (fraction - 0.5) * LENGTH
    vru = {
        "type": "cyclist", "start": [x_hit, y0 + side * 0.0], "heading_deg": -90.0 if from_left else 90.0,
        "top_speed_mps": moto, "initial_speed_mps": moto, "radius_m": radius,
    }  # fmt: skip
    ego = {"cruise_speed_mps": speed, "reverse": reverse}
    result = row(scenario(ego, [vru], duration_s=3.0))
    assert result["collided"]
    assert result["impact_body_side"] == ("left" if from_left else "right")
    assert result["impact_location"] == pytest.approx(fraction, abs=1e-6)
    assert result["contact_time_s"] == pytest.approx(1.0, abs=1e-9)


@settings(max_examples=20, deadline=None)
@given(fraction=st.floats(0.05, 0.95), reverse=st.booleans())
def test_front_and_rear_impact_location_is_the_fraction_of_width(fraction, reverse):
    """A stationary child at `fraction` of the width (0 = right edge of the body) in the leading edge's path."""
    m = -1.0 if reverse else 1.0
    y_body = (fraction - 0.5) * WIDTH
    child = {"type": "pedestrian", "start": [m * 8.0, y_body], "heading_deg": 90.0, "top_speed_mps": 0.0}
    result = row(scenario({"cruise_speed_mps": 2.0, "reverse": reverse}, [child], duration_s=6.0))
    assert result["impact_body_side"] == ("rear" if reverse else "front")
    assert result["impact_side"] == "front"  # the simulated frame's leading edge
    assert result["impact_location"] == pytest.approx(fraction, abs=1e-6)


# ------------------------------------------------------------------------------------------------ ACPE, reversing


def pedal_misapplication(planner: str, **params):
    """CPMFC: creep at 1.5 m/s, full accelerator (4 m/s^2 to 5 m/s, UNVERIFIED) after 1.0 m; a stationary child
    at 50 % of the width 1.75 m ahead of the front bumper at T_ACC (LSC26 §3.2.2.3: 1.5 + [0.5] m)."""
    front0 = LENGTH / 2
    driver = {
        "creep_speed_mps": 1.5,
        "phases": [
            {"at_time_s": 0.0, "target_speed_mps": 1.5, "accel_mps2": 1.0, "accelerator": False},
            {"ego_route_m": 1.0, "target_speed_mps": 5.0, "accel_mps2": 4.0},
        ],
    }
    radius = 0.2
    child = {"type": "pedestrian", "start": [front0 + 1.0 + 1.75 + radius, 0.0], "heading_deg": 90.0,
             "top_speed_mps": 0.0, "radius_m": radius}  # fmt: skip
    return scenario({"initial_speed_mps": 0.0, "cruise_speed_mps": 1.5, "driver": driver}, [child], planner, params)


def test_pedal_misapplication_hits_the_child_without_acpe_and_not_with_it():
    assert row(pedal_misapplication("none"))["collided"]
    result = row(pedal_misapplication("acpe"))
    assert not result["collided"]
    assert result["first_mode_s"]["suppress"] is not None and result["first_mode_s"]["brake"] is not None


def test_acpe_suppression_alone_keeps_the_ego_creeping():
    """Without braking ACPE cuts the accelerator (LSC26 §5.2.2 green): the ego hits at about its creep speed."""
    plain, cut = row(pedal_misapplication("none")), row(pedal_misapplication("acpe", brake_decel_mps2=0.0))
    assert cut["collided"]
    assert cut["impact_ego_speed_mps"] <= 1.5 + 4.0 * DT < plain["impact_ego_speed_mps"]


def reversing_child(planner: str):
    """CPMRCs: reversing from rest to 8 km/h toward a stationary child at 50 % of the width behind."""
    driver = {"phases": [{"at_time_s": 0.0, "target_speed_mps": 8 / 3.6, "accel_mps2": 1.5}]}
    child = {"type": "pedestrian", "start": [-(LENGTH / 2 + 6.0), 0.0], "heading_deg": 90.0, "top_speed_mps": 0.0}
    ego = {"reverse": True, "initial_speed_mps": 0.0, "cruise_speed_mps": 8 / 3.6, "driver": driver}
    return scenario(ego, [child], planner)


def test_reverse_aeb_stops_before_the_child_the_none_planner_hits():
    hit = row(reversing_child("none"))
    assert hit["collided"] and hit["impact_body_side"] == "rear"
    assert not row(reversing_child("reverse_aeb"))["collided"]


def test_reverse_aeb_refuses_a_forward_ego():
    with pytest.raises(UserInputError, match=r"ego\.reverse"):
        simulate([scenario({}, [FAR], "reverse_aeb")])


def test_door_and_driver_batches_compact_like_the_rest():
    """A batch mixing door, driver and plain variants gives each the result it gets alone."""
    batch = [dooring("none"), copy.deepcopy(dooring("none", distance_m=3.0))]
    together = summary_rows(simulate(batch))
    alone = [row(s) for s in batch]
    assert together == alone
