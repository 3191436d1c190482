"""SynchronizeAction and LongitudinalDistanceAction import (issue 19): hand-written files in
tests/data/xosc/synchronize/ run with planner `none` against hand-derived motion (<= 0.01 s, <= 0.02 m); a VUT that
brakes (`fsm`) leaves the VRU's arrival unchanged; constructs vrusim cannot represent are refused (exit 2) naming
the element and its line.

In every sync file the ego's reference point (rear axle) starts at x = -28.85 at 10 m/s and the master target is
x = 1.15 (route station 30 m, t = 3 s at 10 m/s); vru0 starts at (0, -6.14) walking along +y and its target is
y = -1.75 (4.39 m on)."""

from __future__ import annotations

import contextlib
import math
import shutil
import tempfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from fuzz_inputs import mutated_xml
from vrusim.engine.simulate import simulate
from vrusim.errors import UserInputError
from vrusim.formats.xosc_ego_nominal import EgoNominal
from vrusim.formats.xosc_import import read_xosc
from vrusim.formats.xosc_sync_profile import ProfileError, solve_profile
from vrusim.scenario.schema import Ego
from vrusim.sources import apply_planner_and_seed
from xosc_helpers import edited, refused_at

DATA = Path(__file__).parent / "data" / "xosc" / "synchronize"
REAR_TO_CENTRE_M = 1.35
"""The ego's box centre (traced) is this far ahead of its reference point, m."""
MASTER_X_M, TARGET_Y_M, VRU_Y0_M = 1.15, -1.75, -6.14
TIME_TOL_S, DISTANCE_TOL_M = 0.01, 0.02


def _trace(path: Path, planner: str = "none", **parameters: str) -> dict[str, np.ndarray]:
    scenario = apply_planner_and_seed(read_xosc(path, parameters or None), planner)
    return simulate([scenario], trace=True).trace


def _series(trace: dict[str, np.ndarray], key: str) -> np.ndarray:
    return trace[key].reshape(len(trace["t_s"]), -1)[:, 0]


def _at(trace: dict[str, np.ndarray], key: str, t_s: float) -> float:
    return float(np.interp(t_s, trace["t_s"], _series(trace, key)))


def _when(trace: dict[str, np.ndarray], key: str, value: float) -> float:
    """The first time `key` (increasing) reaches `value`, linear between steps."""
    series = _series(trace, key)
    index = int(np.argmax(series >= value))
    assert series[index] >= value, (key, value)
    t0, t1 = trace["t_s"][index - 1], trace["t_s"][index]
    return float(t0 + (value - series[index - 1]) / (series[index] - series[index - 1]) * (t1 - t0))


def _copy(tmp_path: Path, name: str) -> Path:
    shutil.copy(DATA / "road.xodr", tmp_path / "road.xodr")
    shutil.copy(DATA / name, tmp_path / name)
    return tmp_path / name


def _edited(tmp_path: Path, name: str, *pairs: tuple[str, str]) -> Path:
    path = _copy(tmp_path, name)
    for old, new in pairs:
        edited(path, old, new)
    return path


# --------------------------------------------------------------------------------------------- synchronised arrival

ARRIVALS = [
    # file, arrival time (s), speed at arrival (m/s)
    ("sync_no_final_speed.xosc", 3.0, 2 * 4.39 / 3.0),
    ("sync_arrival_steady_distance.xosc", 3.0, 2.0),
    ("sync_final_speed_route_start.xosc", 3.0, 3.0),
    ("sync_relative_steady_time.xosc", 3.0, 2.5),
    ("sync_ego_driver.xosc", 3.0 + 4.0 / 6.0, 2 * 4.39 / (3.0 + 4.0 / 6.0)),
    ("sync_slower_final_speed.xosc", 3.0, 1.0),
]


@pytest.mark.parametrize(("name", "arrival_s", "speed_mps"), ARRIVALS)
def test_the_vru_reaches_its_target_when_the_ego_reaches_the_master_target(name, arrival_s, speed_mps):
    trace = _trace(DATA / name)
    assert abs(_when(trace, "vru_y_m", TARGET_Y_M) - arrival_s) <= TIME_TOL_S
    assert abs(_when(trace, "ego_x_m", MASTER_X_M + REAR_TO_CENTRE_M) - arrival_s) <= TIME_TOL_S
    assert abs(_at(trace, "vru_y_m", arrival_s) - TARGET_Y_M) <= DISTANCE_TOL_M
    assert abs(_at(trace, "vru_speed_mps", arrival_s) - speed_mps) <= 0.01


@pytest.mark.parametrize(
    ("name", "steady_from_s", "steady_m", "speed_mps"),
    [("sync_arrival_steady_distance.xosc", 1.5, 3.0, 2.0), ("sync_relative_steady_time.xosc", 2.0, 2.5, 2.5)],
)
def test_the_steady_state_holds_the_final_speed_over_its_distance(name, steady_from_s, steady_m, speed_mps):
    trace = _trace(DATA / name)
    assert abs(_at(trace, "vru_y_m", steady_from_s) - (TARGET_Y_M - steady_m)) <= DISTANCE_TOL_M
    for t_s in np.linspace(steady_from_s + 0.02, 3.0, 5):
        assert abs(_at(trace, "vru_speed_mps", float(t_s)) - speed_mps) <= 1e-6


def test_the_vru_holds_then_ramps_as_derived_by_hand():
    """Arrival file: standing 0.11 s, 1.39 s at 2/1.39 m/s^2 (1.39 m), then 2 m/s."""
    trace = _trace(DATA / "sync_arrival_steady_distance.xosc")
    assert abs(_at(trace, "vru_y_m", 0.1) - VRU_Y0_M) <= 1e-9
    for t_s in (0.5, 1.0, 1.4):
        walked = 0.5 * (2.0 / 1.39) * (t_s - 0.11) ** 2
        assert abs(_at(trace, "vru_y_m", t_s) - (VRU_Y0_M + walked)) <= DISTANCE_TOL_M


def test_a_braking_vut_does_not_change_the_vru_arrival():
    path = DATA / "sync_arrival_steady_distance.xosc"
    free, braking = _trace(path, "none"), _trace(path, "fsm")
    assert _at(braking, "ego_x_m", 3.0) < _at(free, "ego_x_m", 3.0) - 1.0  # the fsm planner brakes
    assert abs(_when(braking, "vru_y_m", TARGET_Y_M) - 3.0) <= TIME_TOL_S
    for t_s in (0.5, 1.5, 2.5, 3.0):
        assert abs(_at(braking, "vru_y_m", t_s) - _at(free, "vru_y_m", t_s)) <= 1e-9


def test_a_tolerance_moves_the_targets_to_where_they_are_first_within_it():
    """targetToleranceMaster 5: the ego arrives at station 25 (t = 2.5 s); targetTolerance 1: vru0 at y = -2.75."""
    trace = _trace(DATA / "sync_no_final_speed.xosc", MasterTolerance="5.0", Tolerance="1.0")
    assert abs(_when(trace, "vru_y_m", TARGET_Y_M - 1.0) - 2.5) <= TIME_TOL_S


@settings(max_examples=40, deadline=None)
@given(
    final=st.floats(0.5, 6.0),
    steady=st.floats(0.0, 4.39),
    v0=st.sampled_from([0.0, 0.5, 1.5]),
)
def test_an_imported_profile_arrives_at_time_and_speed_or_isrefused_at(final, steady, v0):
    """The imported fields, integrated in closed form, reach 4.39 m at t = 3 s at the final speed, the last
    `steady` m at that speed; or the import is refused at the <FinalSpeed> line."""
    parameters = {"FinalSpeed": repr(final), "SteadyDistance": repr(steady), "VruSpeed": repr(v0)}
    try:
        vru = read_xosc(DATA / "sync_arrival_steady_distance.xosc", parameters).vrus[0]
    except UserInputError as error:
        assert "<FinalSpeed>" in str(error) or "<SynchronizeAction>" in str(error), error
        return
    start = vru.trigger.at_time_s
    assert vru.initial_speed_mps == v0 and start is not None
    top, rate = vru.speed_mps, vru.accel_mps2
    ramp_s = abs(top - v0) / rate if top != v0 else 0.0
    walked = v0 * start + 0.5 * (v0 + top) * ramp_s + top * (3.0 - start - ramp_s)
    assert math.isclose(walked, 4.39, abs_tol=1e-6)
    assert math.isclose(top, final, abs_tol=1e-9)
    assert start + ramp_s <= 3.0 - steady / final + 1e-6


@settings(max_examples=200, deadline=None)
@given(
    v0=st.floats(0.0, 5.0),
    distance=st.floats(0.5, 50.0),
    time=st.floats(0.5, 20.0),
    final=st.none() | st.floats(0.0, 8.0),
    steady=st.none() | st.floats(0.0, 20.0),
)
def test_a_solved_profile_covers_the_distance_in_the_time(v0, distance, time, final, steady):
    try:
        profile = solve_profile(v0, distance, time, final, steady if final is not None else None)
    except ProfileError:
        return
    ramp = abs(profile.top_mps - v0) / profile.rate_mps2 if profile.rate_mps2 else 0.0
    assert profile.delay_s >= 0.0 and profile.delay_s + ramp <= time * (1 + 1e-9) + 1e-9
    walked = (
        v0 * profile.delay_s + 0.5 * (v0 + profile.top_mps) * ramp + profile.top_mps * (time - profile.delay_s - ramp)
    )
    assert math.isclose(walked, distance, rel_tol=1e-9, abs_tol=1e-6)
    if final is not None:
        assert math.isclose(profile.top_mps, final, abs_tol=1e-9)
        if steady is not None and final > 0:
            assert profile.delay_s + ramp <= time - steady / final + 1e-6


# --------------------------------------------------------------------------------------------- longitudinal distance


def test_a_longitudinal_distance_places_the_entity_relative_to_the_ego():
    scenario = read_xosc(DATA / "longitudinal_distance.xosc")
    start = scenario.vrus[0].start
    assert math.isclose(start.x_m, -13.85, abs_tol=1e-9) and math.isclose(start.y_m, VRU_Y0_M, abs_tol=1e-9)
    centre = scenario.obstacles[0].centre
    assert math.isclose(centre.x_m, -3.0, abs_tol=1e-6) and math.isclose(centre.y_m, 1.75, abs_tol=1e-6)
    trace = _trace(DATA / "longitudinal_distance.xosc")
    assert abs(_at(trace, "vru_x_m", 2.0) - -13.85) <= DISTANCE_TOL_M
    assert abs(_at(trace, "vru_y_m", 2.0) - (VRU_Y0_M + 2.0)) <= DISTANCE_TOL_M


@pytest.mark.parametrize(
    ("old", "new", "vru_x_m", "car_x_m"),
    [
        ("leadingReferencedEntity", "trailingReferencedEntity", -28.85 - 15.0, -3.0),
        ('timeGap="$TimeGap" freespace="false"', 'distance="5" freespace="true"', -28.85 + 3.6 + 5.0 + 0.25, -3.0),
        ('distance="$Gap" freespace="true"', 'distance="$Gap" freespace="false"', -13.85, -28.85 + 20.0 - 1.35),
    ],
)
def test_displacement_and_freespace(tmp_path, old, new, vru_x_m, car_x_m):
    scenario = read_xosc(_edited(tmp_path, "longitudinal_distance.xosc", (old, new)))
    assert math.isclose(scenario.vrus[0].start.x_m, vru_x_m, abs_tol=1e-6)
    assert math.isclose(scenario.obstacles[0].centre.x_m, car_x_m, abs_tol=1e-6)


# --------------------------------------------------------------------------------------------- refusals

_SYNC_LINE = "<PrivateAction><SynchronizeAction"
_SPEED_ACTION = """        <PrivateAction><LongitudinalAction><SpeedAction><!-- extra -->
          <SpeedActionDynamics dynamicsShape="step" dynamicsDimension="time" value="0.0"/>
          <SpeedActionTarget><AbsoluteTargetSpeed value="1.0"/></SpeedActionTarget>
        </SpeedAction></LongitudinalAction></PrivateAction>
      </Action>
      <Action name="sync_action2">
"""
_ACTION = '      <Action name="sync_action">\n'
_WITH_SPEED_CHANGE = (_ACTION, '      <Action name="walk_action">\n' + _SPEED_ACTION)
_SECOND_SYNC = (
    _ACTION,
    _ACTION
    + '        <PrivateAction><SynchronizeAction masterEntityRef="ego"><TargetPositionMaster>'
    + '<WorldPosition x="1.15" y="-1.75"/></TargetPositionMaster><TargetPosition><WorldPosition x="0" y="-1.75"/>'
    + "</TargetPosition></SynchronizeAction></PrivateAction>\n      </Action>\n"
    + '      <Action name="sync_action2">\n',
)
_PLACE_EVENT = (
    'coordinateSystem="entity"/></LongitudinalAction></PrivateAction>\n      </Action>\n      <StartTrigger>\n'
    + '          <ConditionGroup><Condition name="c" delay="0.0" conditionEdge="none"><ByValueCondition>'
    + '<SimulationTimeCondition value="{}"'
)
_LATER_PLACEMENT = (_PLACE_EVENT.format("0.0"), _PLACE_EVENT.format("1.0"))

REFUSALS = [
    ("sync_no_final_speed.xosc", [('masterEntityRef="ego"', 'masterEntityRef="vru0"')], _SYNC_LINE,
     ["<SynchronizeAction>", "only the ego can be the master"]),
    ("sync_no_final_speed.xosc", [('<EntityRef entityRef="vru0"/></Actors>', '<EntityRef entityRef="ego"/></Actors>')],
     _SYNC_LINE, ["<SynchronizeAction>", "'ego' is not a VRU"]),
    ("sync_no_final_speed.xosc", [('<WorldPosition x="0.0" y="$TargetY"', '<WorldPosition x="0.5" y="$TargetY"')],
     "<TargetPosition>", ["<TargetPosition>", "not within 0.01 m of the VRU's path"]),
    ("sync_no_final_speed.xosc", [('x="$MasterX" y="-1.75"', 'x="$MasterX" y="0.0"')], "<TargetPositionMaster>",
     ["<TargetPositionMaster>", "never comes within"]),
    ("sync_no_final_speed.xosc", [('name="TargetY" parameterType="double" value="-1.75"',
                                   'name="TargetY" parameterType="double" value="-8.0"')],
     "<TargetPosition>", ["<TargetPosition>", "not within"]),
    ("sync_no_final_speed.xosc", [('name="MasterX" parameterType="double" value="1.15"',
                                   'name="MasterX" parameterType="double" value="-40.0"')],
     "<TargetPositionMaster>", ["<TargetPositionMaster>"]),
    ("sync_final_speed_route_start.xosc", [('name="FinalSpeed" parameterType="double" value="3.0"',
                                            'name="FinalSpeed" parameterType="double" value="1.0"')],
     "<AbsoluteSpeed", ["<FinalSpeed>", "vrusim's VRU changes its speed once"]),
    ("sync_arrival_steady_distance.xosc", [('name="SteadyDistance" parameterType="double" value="3.0"',
                                            'name="SteadyDistance" parameterType="double" value="6.0"')],
     "<TargetDistanceSteadyState", ["<FinalSpeed>", "steady state", "longer than the way"]),
    ("sync_final_speed_route_start.xosc", [('<AbsoluteSpeed value="$FinalSpeed"/>',
                                            '<AbsoluteSpeed value="3.0"><TargetDistanceSteadyState distance="3.0"/>'
                                            "</AbsoluteSpeed>")],
     _SYNC_LINE, ["<SynchronizeAction>", "only when it starts at a simulation time"]),
    ("sync_relative_steady_time.xosc", [('speedTargetValueType="factor" value="$Factor"',
                                         'speedTargetValueType="delta" value="-11"')],
     "<TargetTimeSteadyState", ["<FinalSpeed>", "below 0"]),
    ("sync_no_final_speed.xosc", [_WITH_SPEED_CHANGE], "<!-- extra -->",
     ["<LongitudinalAction>", "no other speed change"]),
    ("sync_no_final_speed.xosc", [_SECOND_SYNC], '<SynchronizeAction masterEntityRef="ego" targetToleranceMaster',
     ["already synchronised"]),
    ("sync_no_final_speed.xosc", [('masterEntityRef="ego" targetToleranceMaster="$MasterTolerance"',
                                   'masterEntityRef="ego" targetToleranceMaster="-1"')],
     _SYNC_LINE, ["targetToleranceMaster must be >= 0"]),
    ("longitudinal_distance.xosc", [('continuous="false" displacement="leadingReferencedEntity"',
                                     'continuous="true" displacement="leadingReferencedEntity"')],
     'timeGap="$TimeGap"', ["<LongitudinalDistanceAction>", "continuous true", "do not follow the ego"]),
    ("longitudinal_distance.xosc", [('displacement="leadingReferencedEntity"/>',
                                     'displacement="leadingReferencedEntity">\n<DynamicConstraints maxAcceleration="1" '
                                     'maxDeceleration="1" maxSpeed="5"/></LongitudinalDistanceAction>')],
     "<DynamicConstraints", ["<DynamicConstraints>", "is not supported"]),
    ("longitudinal_distance.xosc", [('coordinateSystem="entity"', 'coordinateSystem="road"')],
     'distance="$Gap"', ["<LongitudinalDistanceAction>", "coordinateSystem"]),
    ("longitudinal_distance.xosc", [('timeGap="$TimeGap" freespace', 'timeGap="$TimeGap" distance="3" freespace')],
     'timeGap="$TimeGap"', ["exactly one of the attributes distance and timeGap"]),
    ("longitudinal_distance.xosc", [('LongitudinalDistanceAction entityRef="ego" timeGap',
                                     'LongitudinalDistanceAction entityRef="nobody" timeGap')],
     'entityRef="nobody"', ["<LongitudinalDistanceAction>", "names no entity"]),
    ("longitudinal_distance.xosc", [_LATER_PLACEMENT], 'distance="$Gap"',
     ["<LongitudinalDistanceAction>", "simulation time 0"]),
    # 1e308 was a math domain error (the VRU's heading) or a ZeroDivisionError (its box centre): now the number bound
    *((name, [(old, new)], new, [f"<{tag}> attribute {attribute}", "VRUSIM_LIMIT_XML_NUMBER"])
      for name in ("sync_arrival_steady_distance.xosc", "sync_relative_steady_time.xosc",
                   "sync_final_speed_route_start.xosc")
      for old, new, tag, attribute in (
          ('y="-6.14" h="1.570796327"', 'y="-6.14" h="1e308"', "WorldPosition", "h"),
          ('<Center x="0.0" y="0.0" z="0.9"/>', '<Center x="1e308" y="0.0" z="0.9"/>', "Center", "x"))),
]  # fmt: skip


@pytest.mark.parametrize(("name", "pairs", "marker", "words"), REFUSALS)
def test_an_unrepresentable_construct_is_refused_with_its_line(tmp_path, name, pairs, marker, words):
    refused_at(_edited(tmp_path, name, *pairs), marker, *words)


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data())
def test_a_mutated_sync_file_imports_or_is_a_user_error(data):
    text = data.draw(mutated_xml((DATA / "sync_arrival_steady_distance.xosc").read_text()))
    with tempfile.TemporaryDirectory() as folder:
        path = _copy(Path(folder), "sync_arrival_steady_distance.xosc")
        path.write_text(text, encoding="utf-8", errors="surrogatepass")
        with contextlib.suppress(UserInputError):
            read_xosc(path)


def test_the_ego_nominal_motion_follows_its_driver_phases_in_closed_form():
    """10 m/s; from route station 20 m (t = 2 s) down to 6 m/s at 2 m/s^2 (16 m in 2 s), then 6 m/s."""
    phases = [
        {"at_time_s": 0.0, "target_speed_mps": 10.0, "accel_mps2": 2.0},
        {"ego_route_m": 20.0, "target_speed_mps": 6.0, "accel_mps2": 2.0, "accelerator": False},
    ]
    ego = Ego.model_validate({"start": {"x_m": 0, "y_m": 0, "heading_deg": 0}, "cruise_speed_mps": 10.0,
                              "driver": {"phases": phases}})  # fmt: skip
    nominal = EgoNominal(ego)
    t_s, v_mps = nominal.time_at_station(30.0)
    assert math.isclose(t_s, 2.0 + 5.0 - math.sqrt(15.0)) and math.isclose(v_mps, 10.0 - 2.0 * (t_s - 2.0))
    assert math.isclose(nominal.time_at_station(40.0)[0], 4.0 + 4.0 / 6.0)
    assert math.isclose(nominal.station_at_time(5.0), 36.0 + 6.0)
