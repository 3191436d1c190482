"""The `aeb` planner: stage onsets at the analytic TTC, hysteresis, hold and resume, warnings, parameter errors."""

from __future__ import annotations

import numpy as np
import pytest

from vrusim.engine.simulate import simulate
from vrusim.errors import UserInputError
from vrusim.planners.aeb import CRUISE, FULL_BRAKE, PARTIAL_BRAKE, WARNING, AebPlanner
from vrusim.sim.observation import Observation
from vrusim.sim.params import pack

SPEED = 10.0
FRONT_X = 2.25
"""Front bumper of the conftest ego at the start (centre at the origin, 4.5 m long)."""
RADIUS = 0.5


def stationary_target(make_scenario, gap_m: float, **params):
    """Ego at 10 m/s on a straight road towards a stationary pedestrian `gap_m` ahead of its front bumper."""
    return make_scenario(
        {
            "planner": {"name": "aeb", "params": params},
            "sensor": {"range_m": 150.0, "fov_deg": 120.0},
            "vrus": [
                {
                    "type": "pedestrian",
                    "radius_m": RADIUS,
                    "start": {"x_m": FRONT_X + gap_m + RADIUS, "y_m": 0.0},
                    "heading_deg": 90.0,
                    "top_speed_mps": 0.0,
                }
            ],
            "sim": {"duration_s": 8.0},
        }
    )


def first_step_at_or_below(gap_m: float, ttc_s: float, dt: float = 0.01) -> float:
    """Time of the first step at which gap / v <= ttc at constant speed (gap chosen so no step hits it exactly)."""
    return float(np.ceil((gap_m / SPEED - ttc_s) / dt) * dt)


def test_warning_and_partial_braking_start_at_their_ttc(make_scenario):
    gap = 40.05  # TTC 4.005 s: each threshold falls half-way through a step
    run = simulate([stationary_target(make_scenario, gap)])
    first = dict(zip(run.mode_names, run.metrics.first_mode_s[0], strict=True))
    assert first["warning"] == pytest.approx(first_step_at_or_below(gap, 2.6), abs=1e-9)
    assert first["partial_brake"] == pytest.approx(first_step_at_or_below(gap, 1.6), abs=1e-9)
    # the engine records the warning with the TTC of the state it was issued on: just below 2.6 s
    assert run.metrics.first_warning_s[0] == pytest.approx(first["warning"], abs=1e-9)
    assert 2.6 - 0.01 < run.metrics.warning_ttc_s[0] <= 2.6
    assert not run.metrics.collided[0]


def test_full_braking_starts_at_its_ttc(make_scenario):
    # a negligible partial deceleration keeps the speed constant up to the full-braking threshold
    gap = 40.05
    run = simulate([stationary_target(make_scenario, gap, partial_decel_mps2=1e-9)])
    first = dict(zip(run.mode_names, run.metrics.first_mode_s[0], strict=True))
    assert first["full_brake"] == pytest.approx(first_step_at_or_below(gap, 0.9), abs=1e-9)
    assert not run.metrics.collided[0]


def _observer(scenario):
    """Feed an AebPlanner hand-made observations: ego at `station` and `speed`, one VRU at (x, y) at rest."""
    params = pack([scenario])
    planner = AebPlanner()
    planner.reset(params)
    dt = params.dt_s
    state = {"t": 0.0}

    def observe(station: float, speed: float, vru_x: float, vru_y: float = 0.0) -> int:
        x, y, hx, hy, _ = params.routes.locate(params.route_offset, np.array([station]))
        estimate = np.zeros((7, 1, 1))
        estimate[0], estimate[1] = vru_x, vru_y
        obs = Observation(
            state["t"], dt, x, y, hx, hy, np.array([speed]), np.zeros(1), np.array([station]),
            params.cruise_speed_mps, params.rear_to_front_m, params.half_width_m, 2.0 * params.half_length_m,
            params.routes,
            params.route_offset, np.ones((1, 1), dtype=bool), np.ones((1, 1), dtype=np.int8), estimate,
            params.vru_radius_m,
        )  # fmt: skip
        planner.act(obs)
        state["t"] += dt
        return int(planner.mode[0])

    return observe, planner


def test_stages_escalate_at_once_and_release_only_past_threshold_plus_hysteresis(make_scenario):
    observe, planner = _observer(stationary_target(make_scenario, 40.0, hysteresis_s=0.5))

    def at(ttc: float) -> int:  # target placed at TTC `ttc` ahead of the ego's front bumper (station 0, 10 m/s)
        return observe(0.0, SPEED, FRONT_X + ttc * SPEED + RADIUS)

    assert at(3.0) == CRUISE
    assert at(2.55) == WARNING
    assert at(1.55) == PARTIAL_BRAKE
    assert planner.warning[0]
    assert at(0.85) == FULL_BRAKE
    assert at(1.35) == FULL_BRAKE  # 1.35 <= 0.9 + 0.5: held
    assert at(1.45) == PARTIAL_BRAKE  # past 0.9 + 0.5, still <= 1.6 + 0.5
    assert at(2.05) == PARTIAL_BRAKE
    assert at(2.15) == WARNING  # past 1.6 + 0.5, still <= 2.6 + 0.5
    assert at(3.05) == WARNING
    assert at(3.15) == CRUISE
    assert not planner.warning[0]
    assert at(2.55) == WARNING  # and escalates again at once


def test_braking_is_held_to_a_standstill_and_cruise_resumes_once_the_vru_has_left(make_scenario):
    scenario = make_scenario(
        {
            "planner": {"name": "aeb"},
            "sensor": {"range_m": 150.0},
            "vrus": [
                {  # stands in the lane, then walks out of it to the left
                    "type": "pedestrian",
                    "start": {"x_m": 40.0, "y_m": 0.0},
                    "heading_deg": 90.0,
                    "top_speed_mps": 1.5,
                    "trigger": {"at_time_s": 7.0},
                }
            ],
            "ego": {"route": {"length_m": 80.0}},
            "sim": {"duration_s": 20.0},
        }
    )
    run = simulate([scenario], trace=True)
    trace = run.trace
    speed = trace["ego_speed_mps"][:, 0]
    names = [run.mode_names[m] for m in trace["planner_mode"][:, 0]]
    assert not run.metrics.collided[0]
    stopped = np.flatnonzero(speed == 0.0)
    assert stopped.size, "the AEB brakes to a standstill in front of the pedestrian"
    t = trace["t_s"]
    # held while the pedestrian is in the path: braking stage all the way from the first stop to the trigger
    assert all(names[i] in ("partial_brake", "full_brake") for i in range(stopped[0], int(7.0 / 0.01) - 1))
    resumed = next(i for i in range(stopped[0], len(names)) if names[i] == "cruise")
    assert t[resumed] > 7.0
    assert run.metrics.travel_time_s[0] > 0  # drove on to the end of its route


def test_warning_flag_follows_the_stages(make_scenario):
    run = simulate([stationary_target(make_scenario, 40.05)], trace=True)
    assert run.mode_names == ("cruise", "warning", "partial_brake", "full_brake")
    assert np.isfinite(run.metrics.first_warning_s[0])


@pytest.mark.parametrize(
    ("params", "field", "message"),
    [
        ({"partial_ttc_s": 3.0}, "partial_ttc_s", "at most warning_ttc_s"),
        ({"full_ttc_s": 2.0}, "full_ttc_s", "at most partial_ttc_s"),
        ({"full_decel_mps2": 2.0}, "full_decel_mps2", "at least partial_decel_mps2"),
        ({"warning_ttc_s": 0.0}, "warning_ttc_s", "greater than 0"),
        ({"hysteresis_s": float("nan")}, "hysteresis_s", "finite"),
        ({"brake_hard": True}, "brake_hard", "unknown field"),
    ],
)
def test_bad_parameters_name_the_field(make_scenario, params, field, message):
    with pytest.raises(UserInputError, match=rf"planner\.params\.{field}: .*{message}"):
        simulate([stationary_target(make_scenario, 40.0, **params)])


@pytest.mark.parametrize(("gap_m", "lead_mps", "decel_mps2"), [(20.0, 8.0, 4.0), (12.0, 5.0, 6.0), (30.0, 6.0, 1.0)])
def test_route_ttc_of_a_braking_lead_matches_the_closed_form(gap_m, lead_mps, decel_mps2):
    """Ego at 10 m/s on a straight route, a lead `gap_m` ahead braking to a stop: the gap closes as
    gap + u t - d t^2 / 2 - v t while the lead moves, as gap + u^2 / 2d - v t once it stands."""
    from vrusim.geometry.path_table import PathTable
    from vrusim.geometry.paths import Line, PathSpec
    from vrusim.planners.route_ttc import route_ttc

    table = PathTable([PathSpec(0.0, 0.0, 0.0, (Line(500.0),))])
    half_length, half_width, rear_to_centre = 2.25, 0.9, 0.9  # rear axle at 0: the front bumper at 3.15 m
    x = 3.15 + gap_m + RADIUS
    u, d, v = lead_mps, decel_mps2, SPEED
    stop_s = u / d
    moving = np.roots([0.5 * d, v - u, -gap_m])  # contact while the lead still moves, if before it stops
    moving = [t for t in moving.real if 0 <= t <= stop_s]
    expected = min(moving) if moving else (gap_m + u * u / (2 * d)) / v
    got = route_ttc(table.arrays, 0, 0.0, v, rear_to_centre, half_length, half_width, x, 0.0, u, 0.0, d, RADIUS, 10.0)
    assert got == pytest.approx(expected, abs=2e-3)  # linear interpolation between 0.05 s samples
    constant = route_ttc(
        table.arrays, 0, 0.0, v, rear_to_centre, half_length, half_width, x, 0.0, u, 0.0, 0.0, RADIUS, 10.0
    )
    assert constant == pytest.approx(gap_m / (v - u), abs=1e-6)  # without braking: gap / closing speed
    assert got < constant


def test_a_braking_lead_is_seen_before_it_has_slowed(make_scenario):
    """Euro NCAP CMRb at 80 km/h: predicting the motorcycle's braking avoids the impact that a constant-velocity
    TTC (`predict_braking: false`) reacts to too late."""
    from vrusim.ncap.build import build_test
    from vrusim.ncap.grid import select

    test = next(t for t in select(protocol="2023", codes=["CMRb"]) if t.cell.vut_speed_kph == 80)
    base = build_test(test, "aeb").scenario
    runs = []
    for predict in (True, False):
        planner = base.planner.model_copy(update={"params": {"predict_braking": predict}})
        runs.append(base.model_copy(update={"planner": planner}))
    predicting, constant = simulate(runs).metrics.collided
    assert not predicting and constant
