"""OpenSCENARIO actions and conditions (issue 19): hand-written files in tests/data/xosc/actions/ run with planner
`none` and checked against analytic motion (<= 0.01 s, <= 0.02 m); constructs vrusim cannot represent exactly are
refused (exit 2) naming the element and its line."""

from __future__ import annotations

import math
import shutil
from pathlib import Path

import numpy as np
import pytest

from cli_helpers import invoke
from vrusim.engine.simulate import simulate
from vrusim.formats.xosc_import import import_xosc, read_xosc
from vrusim.sources import apply_planner_and_seed
from xosc_helpers import edited, refused_at

DATA = Path(__file__).parent / "data" / "xosc" / "actions"
EGO_X0_M = -28.85
"""The ego's reference point (rear axle) at t = 0 in every file, m; it drives along +x at 10 m/s."""
VRU_Y0_M = -6.14
"""The VRU's start in every file, m; it walks along -y."""
TIME_TOL_S, DISTANCE_TOL_M = 0.01, 0.02


def _trace(name: str) -> dict[str, np.ndarray]:
    scenario = apply_planner_and_seed(read_xosc(DATA / name), "none")
    return simulate([scenario], trace=True).trace


def _at(trace: dict[str, np.ndarray], key: str, t_s: float) -> float:
    """`key` of the first variant (and VRU) at `t_s`, linear between steps."""
    values = trace[key].reshape(len(trace["t_s"]), -1)[:, 0]
    assert trace["t_s"][0] <= t_s <= trace["t_s"][-1], t_s
    return float(np.interp(t_s, trace["t_s"], values))


def _walked(trace: dict[str, np.ndarray], t_s: float) -> float:
    """The VRU's distance from its start at `t_s`, m."""
    return VRU_Y0_M - _at(trace, "vru_y_m", t_s)


def _started_at(trace: dict[str, np.ndarray], after_s: float = 0.0) -> float:
    """When a VRU started by a step to 1 m/s started: the time its walked distance extrapolates back to 0, s."""
    t = after_s + 1.0
    return t - _walked(trace, t)


def _copy(tmp_path: Path, name: str) -> Path:
    shutil.copy(DATA / "road.xodr", tmp_path / "road.xodr")
    shutil.copy(DATA / name, tmp_path / name)
    return tmp_path / name


def _edited(tmp_path: Path, name: str, old: str, new: str) -> Path:
    return edited(_copy(tmp_path, name), old, new)


# --------------------------------------------------------------------------------------------- speed dynamics


def test_a_vru_linear_ramp_over_a_time_covers_the_mean_speed_times_its_duration():
    trace = _trace("vru_linear_time.xosc")
    assert abs(_walked(trace, 1.0)) < DISTANCE_TOL_M
    assert abs(_walked(trace, 3.0) - (0.0 + 2.0) / 2 * 2.0) < DISTANCE_TOL_M
    assert abs(_at(trace, "vru_speed_mps", 3.0) - 2.0) < 1e-6
    assert abs(_walked(trace, 5.0) - (2.0 + 2.0 * 2.0)) < DISTANCE_TOL_M


def test_a_vru_linear_ramp_over_a_distance_reaches_its_speed_after_that_distance():
    trace = _trace("vru_linear_distance.xosc")
    duration = 2 * 3.0 / (0.0 + 2.0)  # constant acceleration over 3 m from 0 to 2 m/s
    assert abs(_walked(trace, 1.0 + duration) - 3.0) < DISTANCE_TOL_M
    assert abs(_at(trace, "vru_speed_mps", 1.0 + duration) - 2.0) < 1e-6
    assert _at(trace, "vru_speed_mps", 1.0 + duration - 0.1) < 2.0 - 0.05


def test_a_vru_linear_ramp_at_a_rate():
    trace = _trace("vru_linear_rate.xosc")
    assert abs(_walked(trace, 2.0) - 0.5 * 1.0 * 1.0**2) < DISTANCE_TOL_M
    assert abs(_walked(trace, 4.0) - (2.0 + 2.0)) < DISTANCE_TOL_M


def test_a_vru_step_then_a_stop_over_a_distance_after_its_event():
    trace = _trace("vru_step_and_stop.xosc")
    assert abs(_walked(trace, 3.0) - 1.5 * 2.0) < DISTANCE_TOL_M
    stop_s = 2 * 1.5 / 1.5  # 1.5 m from 1.5 m/s to 0 at constant deceleration
    assert abs(_walked(trace, 3.0 + stop_s) - (3.0 + 1.5)) < DISTANCE_TOL_M
    assert _at(trace, "vru_speed_mps", 3.0 + stop_s) < 1e-6
    assert _at(trace, "vru_speed_mps", 3.0 + stop_s - 0.1) > 0.05


def test_ego_speed_changes_over_a_time_and_at_a_rate_become_driver_phases():
    scenario = read_xosc(DATA / "ego_linear_time.xosc")
    assert scenario.ego.driver is not None and len(scenario.ego.driver.phases) == 3
    trace = _trace("ego_linear_time.xosc")
    assert abs(_at(trace, "ego_station_m", 3.0) - (10.0 + (10.0 + 6.0) / 2 * 2.0)) < DISTANCE_TOL_M
    assert abs(_at(trace, "ego_speed_mps", 3.0) - 6.0) < 1e-6
    assert abs(_at(trace, "ego_station_m", 6.0) - (26.0 + 6.0 + (6.0 + 8.0) / 2 * 2.0)) < DISTANCE_TOL_M
    assert abs(_at(trace, "ego_speed_mps", 6.0) - 8.0) < 1e-6


def test_an_ego_ramp_over_a_distance_reaches_its_speed_after_that_distance():
    trace = _trace("ego_linear_distance.xosc")
    assert abs(_at(trace, "ego_station_m", 3.0) - (10.0 + 16.0)) < DISTANCE_TOL_M
    assert abs(_at(trace, "ego_speed_mps", 3.0) - 6.0) < 1e-6
    assert _at(trace, "ego_speed_mps", 2.9) > 6.1


# --------------------------------------------------------------------------------------------- conditions


@pytest.mark.parametrize(
    ("name", "start_s"),
    [
        ("cond_reach_position.xosc", 10.0 / 10.0),
        ("cond_distance_freespace.xosc", (-3.0 - 3.6 - EGO_X0_M) / 10.0),
        ("cond_relative_distance.xosc", (-math.sqrt(20.0**2 - (6.14 - 1.75) ** 2) - EGO_X0_M) / 10.0),
        ("cond_time_to_collision.xosc", (10.0 - 2.0 * 10.0 - 3.6 - EGO_X0_M) / 10.0),
        ("cond_groups_and_event.xosc", 2.5),
    ],
)
def test_a_vru_starts_when_its_condition_first_holds(name, start_s):
    assert abs(_started_at(_trace(name), start_s) - start_s) < TIME_TOL_S


def test_a_condition_on_the_ego_maps_to_the_route_station():
    trigger = read_xosc(DATA / "cond_reach_position.xosc").vrus[0].trigger
    assert trigger.ego_route_m == pytest.approx(10.0, abs=1e-6)


# --------------------------------------------------------------------------------------------- ignored, lenient


def test_lights_are_ignored_and_listed_and_a_night_event_sets_night():
    result = import_xosc(DATA / "ignored_lights_night.xosc")
    assert result.scenario.sensor.lighting == "night"
    assert len(result.warnings) == 1 and "<AppearanceAction> ignored" in result.warnings[0]
    assert "line 62" in result.warnings[0]


def test_weather_and_controllers_are_errors_unless_lenient(tmp_path):
    path = _copy(tmp_path, "lenient_weather_controller.xosc")
    refused_at(path, "<Weather>", "--lenient")
    out = tmp_path / "out.yaml"
    result = invoke("import", str(path), "--out", str(out), "--lenient")
    assert result.exit_code == 0, result.output
    assert "<Weather> ignored" in result.output and "<ControllerAction> ignored" in result.output
    run = invoke("run", str(path), "--planner", "none", "--lenient", "--json")
    assert run.exit_code == 0, run.output
    assert invoke("run", str(path), "--planner", "none").exit_code == 2


def test_lenient_is_for_a_xosc_only():
    result = invoke("run", "CPNA-25/20kph/day", "--lenient")
    assert result.exit_code == 2 and "--lenient" in result.output


# --------------------------------------------------------------------------------------------- refused

WALK = '<SpeedActionDynamics dynamicsShape="linear" dynamicsDimension="time" value="2.0"/>'
REACH = (
    '<ReachPositionCondition tolerance="5.0"><Position><WorldPosition x="-13.85" y="-1.75"/></Position>'
    "</ReachPositionCondition>"
)
LIGHTS = (
    '<AppearanceAction><LightStateAction transitionTime="0"><LightType><VehicleLight vehicleLightType="headLights"/>'
    '</LightType><LightState mode="on"/></LightStateAction></AppearanceAction>'
)
NIGHT_START = (
    "</Environment></EnvironmentAction></GlobalAction>\n      </Action>\n      <StartTrigger>\n"
    '          <ConditionGroup><Condition name="c" delay="0.0"'
)
REFUSALS = {
    "cubic": ("ego_linear_time.xosc", WALK, WALK.replace('"linear"', '"cubic"'), "cubic", "<SpeedActionDynamics>"),
    "sinusoidal": (
        "ego_linear_time.xosc",
        WALK,
        WALK.replace('"linear"', '"sinusoidal"'),
        "sinusoidal",
        "<SpeedActionDynamics>",
    ),
    "time rule": (
        "vru_linear_time.xosc",
        '"1.0" rule="greaterOrEqual"',
        '"1.0" rule="lessThan"',
        "lessThan",
        "<SimulationTimeCondition>",
        "rule",
    ),
    "speed": (
        "cond_reach_position.xosc",
        REACH,
        '<SpeedCondition value="5.0" rule="equalTo"/>',
        "<SpeedCon",
        "<SpeedCondition>",
        "instant",
    ),
    "standstill": (
        "cond_reach_position.xosc",
        REACH,
        '<StandStillCondition duration="-1.0"/>',
        "<StandStill",
        "<StandStillCondition>",
        "duration",
    ),
    "falling edge": (
        "ego_linear_distance.xosc",
        'delay="0.0" conditionEdge="rising"',
        'delay="0.0" conditionEdge="falling"',
        "<TraveledDistanceCondition",
        "<TraveledDistanceCondition>",
        "falling",
    ),
    "and-ed": (
        "cond_reach_position.xosc",
        "</ByEntityCondition></Condition></ConditionGroup>",
        '</ByEntityCondition></Condition><Condition name="d" delay="0" conditionEdge="none"><ByValueCondition>'
        '<SimulationTimeCondition value="1.0" rule="greaterOrEqual"/></ByValueCondition></Condition>'
        "</ConditionGroup>",
        'conditionEdge="rising"><ByEntityCondition>',
        "<ConditionGroup>",
        "AND",
    ),
    "never reached": (
        "cond_reach_position.xosc",
        'x="-13.85" y="-1.75"',
        'x="-13.85" y="40.0"',
        "<ReachPositionCondition",
        "<ReachPositionCondition>",
        "never comes",
    ),
    "ttc off the route": (
        "cond_time_to_collision.xosc",
        'x="10.0" y="-1.75"',
        'x="10.0" y="0.0"',
        "<TimeToCollisionCondition",
        "<TimeToCollisionCondition>",
        "straight route",
    ),
    "longitudinal distance": (
        "cond_distance_freespace.xosc",
        '"euclidianDistance"',
        '"longitudinal"',
        "<DistanceCondition",
        "<DistanceCondition>",
        "relativeDistanceType",
    ),
    "freespace between entities": (
        "cond_relative_distance.xosc",
        'freespace="false"',
        'freespace="true"',
        "<RelativeDistanceCondition",
        "<RelativeDistanceCondition>",
        "freespace",
    ),
    "time to collision with an entity": (
        "cond_time_to_collision.xosc",
        '<Position><WorldPosition x="10.0" y="-1.75"/></Position></TimeToCollisionConditionTarget>',
        '<EntityRef entityRef="vru0"/></TimeToCollisionConditionTarget>',
        "<TimeToCollisionCondition",
        "<TimeToCollisionCondition>",
        "<Position>",
    ),
    "distance to a moving entity": (
        "cond_relative_distance.xosc",
        '<AbsoluteTargetSpeed value="0.0"/>',
        '<AbsoluteTargetSpeed value="0.5"/>',
        "<RelativeDistanceCondition",
        "<RelativeDistanceCondition>",
        "moves before the trigger",
    ),
    "delayed travel": (
        "ego_linear_distance.xosc",
        'delay="0.0" conditionEdge="rising"',
        'delay="1.0" conditionEdge="rising"',
        "<TraveledDistanceCondition",
        "<TraveledDistanceCondition>",
        "delayed",
    ),
    "ego step": (
        "ego_linear_time.xosc",
        WALK,
        WALK.replace('"linear"', '"step"'),
        'dynamicsShape="step" dynamicsDimension="time" value="2.0"',
        "<SpeedActionDynamics>",
        "step",
    ),
    "ego over its performance": (
        "ego_linear_time.xosc",
        WALK,
        WALK.replace('"2.0"', '"0.2"'),
        'value="0.2"',
        "<SpeedActionDynamics>",
        "max_decel_mps2",
    ),
    "ego overlapping changes": (
        "ego_linear_time.xosc",
        '<SimulationTimeCondition value="4.0"',
        '<SimulationTimeCondition value="2.0"',
        'dynamicsDimension="rate" value="1.0"',
        "<SpeedActionDynamics>",
        "before the previous",
    ),
    "override controller": (
        "ignored_lights_night.xosc",
        LIGHTS,
        "<ControllerAction><OverrideControllerValueAction/></ControllerAction>",
        "<OverrideController",
        "<OverrideControllerValueAction>",
        "changes the motion",
    ),
    "environment after t = 0": (
        "ignored_lights_night.xosc",
        NIGHT_START,
        NIGHT_START.replace('delay="0.0"', 'delay="1.0"'),
        "<GlobalAction>",
        "<GlobalAction>",
        "time 0",
    ),
}


@pytest.mark.parametrize(
    ("name", "old", "new", "marker", "words"), [(*r[:4], r[4:]) for r in REFUSALS.values()], ids=list(REFUSALS)
)
def test_an_unrepresentable_construct_is_refused_with_its_line(tmp_path, name, old, new, marker, words):
    refused_at(_edited(tmp_path, name, old, new), marker, *words)


def test_an_ego_step_at_time_zero_is_its_initial_speed(tmp_path):
    step_event = (
        '<Event name="go" priority="parallel"><Action name="go_action"><PrivateAction><LongitudinalAction>'
        '<SpeedAction><SpeedActionDynamics dynamicsShape="step" dynamicsDimension="time" value="0"/>'
        '<SpeedActionTarget><AbsoluteTargetSpeed value="10.0"/></SpeedActionTarget></SpeedAction>'
        "</LongitudinalAction></PrivateAction></Action><StartTrigger><ConditionGroup>"
        '<Condition name="c" delay="0" conditionEdge="none"><ByValueCondition>'
        '<SimulationTimeCondition value="0" rule="greaterOrEqual"/></ByValueCondition></Condition>'
        "</ConditionGroup></StartTrigger></Event>\n"
    )
    path = _edited(tmp_path, "ego_linear_time.xosc", '<Event name="slow"', step_event + '<Event name="slow"')
    text = path.read_text().replace('<AbsoluteTargetSpeed value="10.0"/>', '<AbsoluteTargetSpeed value="0.0"/>', 1)
    path.write_text(text)
    ego = read_xosc(path).ego
    assert ego.cruise_speed_mps == 10.0 and ego.driver is not None
    assert [p.target_speed_mps for p in ego.driver.phases] == [10.0, 6.0, 8.0]
