"""Export a Scenario as OpenSCENARIO XML 1.3 (`NAME.xosc`) with its OpenDRIVE 1.5 road (`NAME.xodr`).

The export is the test setup, not a simulated run: entities, initial poses and speeds, the ego's route and
cruise speed, every VRU's path, its trigger and speed profile. The planner (its braking), the sensor and V2X
are not exported. Mapping of every field, the coordinate transform and checker results: docs/interop.md.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path

from vrusim.extras import extra

with extra("export"):
    from scenariogeneration import xodr, xosc

from vrusim.interop.opendrive import road_network
from vrusim.interop.osc_entities import (
    ego_reference_pose,
    ego_vehicle,
    obstacle_reference_pose,
    obstacle_vehicle,
    vru_entity,
)
from vrusim.interop.osc_motion import (
    Vertex,
    ego_overrun_m,
    ego_trajectory,
    trigger_station_m,
    vru_reach_m,
    vru_trajectory,
)
from vrusim.interop.osc_speed_triggers import ego_speed_trigger
from vrusim.io.atomic import write_together
from vrusim.scenario.schema import Scenario, Vru
from vrusim.sim.vru.shaped import PEAK_TO_MEAN_RATE
from vrusim.version import __version__

EGO = "ego"
ROAD_MARGIN_M = 10.0
"""The road reaches this far beyond every start position, route vertex and VRU waypoint, m."""


def file_stem(name: str) -> str:
    """A file name stem from a scenario name or test id: '/' and other unsafe characters become '_'."""
    return re.sub(r"[^A-Za-z0-9._-]+", "_", name).strip("._") or "scenario"


def vru_name(index: int) -> str:
    return f"vru{index}"


def _clean(value: float) -> float:
    """`value` at full precision (an import gives back the same number), round-off below 1e-12 written as 0."""
    return 0.0 if abs(value) < 1e-12 else value + 0.0


def _world(x_m: float, y_m: float, heading_rad: float) -> xosc.WorldPosition:
    """A ground-level world position (m, rad) at full precision: rounded to 1e-9 m, a start 4e-10 m off moved a
    night FSM run's first detection by a step on import (`scripts/xosc_round_trip.py`)."""
    return xosc.WorldPosition(_clean(x_m), _clean(y_m), 0.0, _clean(heading_rad))


def _polyline(name: str, vertices: list[Vertex]) -> xosc.Trajectory:
    trajectory = xosc.Trajectory(name, False)
    trajectory.add_shape(xosc.Polyline([], [_world(v.x_m, v.y_m, v.heading_rad) for v in vertices]))
    return trajectory


def _at_time(name: str, time_s: float | str) -> xosc.ValueTrigger:
    condition = xosc.SimulationTimeCondition(time_s, xosc.Rule.greaterOrEqual)
    return xosc.ValueTrigger(name, 0.0, xosc.ConditionEdge.none, condition)


def _travelled(name: str, distance_m: float | str) -> xosc.EntityTrigger:
    return xosc.EntityTrigger(name, 0.0, xosc.ConditionEdge.none, xosc.TraveledDistanceCondition(distance_m), EGO)


def _speed(speed_mps: float | str, rate_mps2: float | str | None, shape: str = "linear") -> xosc.AbsoluteSpeedAction:
    """Reach a speed at a constant rate (m/s^2), or at once (`rate_mps2` None); a cubic or sinusoidal `shape` at
    that peak rate."""
    if rate_mps2 is None:
        dynamics = xosc.TransitionDynamics(xosc.DynamicsShapes.step, xosc.DynamicsDimension.time, 0.0)
    else:
        dynamics = xosc.TransitionDynamics(getattr(xosc.DynamicsShapes, shape), xosc.DynamicsDimension.rate, rate_mps2)
    return xosc.AbsoluteSpeedAction(speed_mps, dynamics)


def _event(name: str, trigger, actions: list) -> xosc.Event:
    event = xosc.Event(name, xosc.Priority.parallel)
    for index, action in enumerate(actions):
        event.add_action(f"{name}_action{index}", action)
    event.add_trigger(trigger)
    return event


def _group(entity: str, events: list[xosc.Event]) -> xosc.ManeuverGroup:
    maneuver = xosc.Maneuver(f"{entity}_maneuver")
    for event in events:
        maneuver.add_event(event)
    group = xosc.ManeuverGroup(f"{entity}_group")
    group.add_actor(entity)
    group.add_maneuver(maneuver)
    return group


class _Parameters:
    """Parameter declarations; `ref` declares one (double, SI units in its name) and returns `$name`."""

    def __init__(self) -> None:
        self.declarations = xosc.ParameterDeclarations()

    def ref(self, name: str, value: float) -> str:
        self.declarations.add_parameter(xosc.Parameter(name, xosc.ParameterType.double, repr(float(value))))
        return f"${name}"


def _vru_rate(vru: Vru, name: str, mean_mps2: float, params: _Parameters) -> tuple[str, str]:
    """(`$parameter`, dynamics shape) of a VRU speed change at mean rate `mean_mps2`: as written for the motion
    models `cubic` and `sinusoidal`, their peak rate (`name` with "Peak"; docs/openscenario_import.md), else
    linear at that rate."""
    if vru.motion not in PEAK_TO_MEAN_RATE:
        return params.ref(f"{name}_mps2", mean_mps2), "linear"
    return params.ref(f"{name}Peak_mps2", mean_mps2 * PEAK_TO_MEAN_RATE[vru.motion]), vru.motion


def _ego_group(scenario: Scenario, params: _Parameters, init: xosc.Init) -> xosc.ManeuverGroup:
    ego = scenario.ego
    sign = -1.0 if ego.reverse else 1.0  # OpenSCENARIO drives backwards at negative speeds
    init.add_init_action(EGO, xosc.TeleportAction(_world(*ego_reference_pose(ego))))
    init.add_init_action(EGO, _speed(params.ref("EgoInitialSpeed_mps", sign * ego.start_speed_mps), None))
    vertices, offset = ego_trajectory(ego, ego_overrun_m(scenario))
    follow = xosc.FollowTrajectoryAction(
        _polyline("ego_route", vertices),
        xosc.FollowingMode.position,
        initialDistanceOffset=offset if offset > 0 else None,
    )
    events = [_event("ego_route", _at_time("ego_route_start", 0.0), [follow])]
    if ego.cruise_speed_mps != ego.start_speed_mps:
        cruise = params.ref("EgoCruiseSpeed_mps", sign * ego.cruise_speed_mps)
        rate = ego.max_accel_mps2 if ego.cruise_speed_mps > ego.start_speed_mps else ego.max_decel_mps2
        events.append(_event("ego_cruise", _at_time("ego_cruise_start", 0.0), [_speed(cruise, rate)]))
    return _group(EGO, events)


def vru_trigger(scenario: Scenario, vru: Vru, name: str, params: _Parameters) -> tuple[object, str] | None:
    """The start condition equivalent to a VRU's trigger, and a note on it; None if it never fires.

    At a time -> SimulationTimeCondition; ego route distance -> the ego's TraveledDistanceCondition (the same
    rear-axle distance); the ego's speed or standstill -> its SpeedCondition or StandStillCondition
    (`osc_speed_triggers`); ego distance or time-to-arrival to a point -> the ego's TraveledDistanceCondition at
    the station where it fires for the exported, non-reacting ego (`osc_motion.trigger_station_m`).
    """
    trigger = vru.trigger
    if trigger.at_time_s is not None:
        value = params.ref(f"{name.capitalize()}TriggerTime_s", trigger.at_time_s)
        return _at_time(f"{name}_trigger", value), f"at t = {trigger.at_time_s!r} s"
    if trigger.ego_route_m is not None:
        value = params.ref(f"{name.capitalize()}TriggerEgoTravel_m", trigger.ego_route_m)
        return _travelled(f"{name}_trigger", value), f"ego travelled {trigger.ego_route_m!r} m"
    on_speed = ego_speed_trigger(trigger, EGO, f"{name}_trigger", params.ref, name.capitalize())
    if on_speed is not None:
        return on_speed
    search = scenario.ego.route.length_m + ego_overrun_m(scenario)
    station = trigger_station_m(scenario.ego, trigger, search)
    if station is None:
        return None
    point = trigger.point
    where = f" of ({point.x_m!r}, {point.y_m!r}) m" if point is not None else ""
    if trigger.ego_distance_m is not None:
        what = f"ego front within {trigger.ego_distance_m!r} m{where}"
    else:
        what = f"ego front within {trigger.ego_time_to_arrival_s!r} s (distance / speed){where}"
    value = params.ref(f"{name.capitalize()}TriggerEgoTravel_m", station)
    return _travelled(f"{name}_trigger", value), f"{what}: ego travelled {station!r} m"


def _vru_group(scenario: Scenario, index: int, params: _Parameters, init: xosc.Init, notes: xosc.Properties):
    vru, name = scenario.vrus[index], vru_name(index)
    prefix = name.capitalize()
    vertices = vru_trajectory(vru, max(vru_reach_m(vru, scenario.sim.duration_s), 1.0))
    init.add_init_action(name, xosc.TeleportAction(_world(vertices[0].x_m, vertices[0].y_m, vertices[0].heading_rad)))
    init.add_init_action(name, _speed(params.ref(f"{prefix}InitialSpeed_mps", vru.initial_speed_mps), None))
    events = []
    if vru_reach_m(vru, scenario.sim.duration_s) > 0.0:
        follow = xosc.FollowTrajectoryAction(_polyline(f"{name}_path", vertices), xosc.FollowingMode.position)
        events.append(_event(f"{name}_path", _at_time(f"{name}_path_start", 0.0), [follow]))
    moves = vru.speed_mps != vru.initial_speed_mps or vru.brake is not None
    start = vru_trigger(scenario, vru, name, params) if moves else None
    if start is not None:
        condition, note = start
        top = params.ref(f"{prefix}TopSpeed_mps", vru.speed_mps)
        accel, shape = _vru_rate(vru, f"{prefix}Accel", vru.accel_mps2, params)
        events.append(_event(f"{name}_start", condition, [_speed(top, accel, shape)]))
        notes.add_property(f"{name}_trigger", note)
        if vru.brake is not None:
            delay = params.ref(f"{prefix}BrakeDelay_s", vru.brake.after_trigger_s)
            decel, shape = _vru_rate(vru, f"{prefix}BrakeDecel", vru.brake.decel_mps2, params)
            started = xosc.StoryboardElementStateCondition(
                xosc.StoryboardElementType.event, f"{name}_start", xosc.StoryboardElementState.startTransition
            )
            trigger = xosc.ValueTrigger(f"{name}_brake_trigger", delay, xosc.ConditionEdge.none, started)
            events.append(_event(f"{name}_brake", trigger, [_speed(0.0, decel, shape)]))
    return _group(name, events) if events else None


def _stop_trigger(scenario: Scenario, params: _Parameters) -> xosc.Trigger:
    """End of the run: its duration, or (as vrusim stops) the ego's route end and the first contact."""
    stop = xosc.Trigger("stop")
    conditions = [_at_time("end_of_run", params.ref("SimDuration_s", scenario.sim.duration_s))]
    if scenario.sim.stop_at_route_end:
        conditions.append(_travelled("route_end", scenario.ego.route.length_m))
    if scenario.sim.stop_on_collision:
        conditions += [
            xosc.EntityTrigger(
                f"contact_{vru_name(k)}", 0.0, xosc.ConditionEdge.none, xosc.CollisionCondition(vru_name(k)), EGO
            )
            for k in range(len(scenario.vrus))
        ]
    for condition in conditions:  # condition groups are OR-ed
        group = xosc.ConditionGroup("stop")
        group.add_condition(condition)
        stop.add_conditiongroup(group)
    return stop


def road_half_length_m(scenario: Scenario) -> float:
    """Half length of each road arm, m: the scenario's, lengthened so every start position, route vertex,
    VRU waypoint and obstacle lies `ROAD_MARGIN_M` inside the road's extent (whole metres)."""
    points = [(scenario.ego.start.x_m, scenario.ego.start.y_m)]
    points += [(v.x_m, v.y_m) for v in ego_trajectory(scenario.ego, 0.0)[0]]
    for vru in scenario.vrus:
        points += [(vru.start.x_m, vru.start.y_m)] + [(p.x_m, p.y_m) for p in vru.path or []]
    for box in scenario.obstacles:
        reach = math.hypot(box.length_m, box.width_m) / 2
        points += [(box.centre.x_m + dx, box.centre.y_m + dy) for dx in (-reach, reach) for dy in (-reach, reach)]
    straight = scenario.road.layout == "straight"
    extent = max(abs(x) if straight else max(abs(x), abs(y)) for x, y in points) + ROAD_MARGIN_M
    return float(max(scenario.road.length_m / 2, math.ceil(extent), scenario.road.lane_width_m + 1.0))


LIGHT_HOURS = {"day": 12, "night": 23}
"""Local hour of the exported `<TimeOfDay>` per `sensor.lighting` (the importer reads 06:00–20:00 as day)."""


def _light(scenario: Scenario) -> xosc.EnvironmentAction:
    """The lighting as an EnvironmentAction with a time of day (no weather, no road condition)."""
    hour = LIGHT_HOURS[scenario.sensor.lighting]
    time_of_day = xosc.TimeOfDay(False, 2026, 1, 15, hour, 0, 0)
    return xosc.EnvironmentAction(xosc.Environment("vrusim_lighting", timeofday=time_of_day))


def openscenario_document(scenario: Scenario, road_file: str) -> xosc.Scenario:
    """The OpenSCENARIO document of a scenario; `road_file` is the LogicFile path (relative to the .xosc)."""
    params, init, notes = _Parameters(), xosc.Init(), xosc.Properties()
    notes.add_property("vrusim_version", __version__)
    notes.add_property("vrusim_scenario", scenario.name)
    if scenario.road.lines is not None or scenario.road.surfaces is not None:
        notes.add_property("vrusim_road", DRAWN_ROAD_NOTE)
    entities = xosc.Entities()
    entities.add_scenario_object(EGO, ego_vehicle(scenario.ego))
    act = xosc.Act("vrusim_act", _at_time("act_start", 0.0))
    act.add_maneuver_group(_ego_group(scenario, params, init))
    for index, vru in enumerate(scenario.vrus):
        entities.add_scenario_object(vru_name(index), vru_entity(vru, vru_name(index)))
        group = _vru_group(scenario, index, params, init, notes)
        if group is not None:
            act.add_maneuver_group(group)
    for index, box in enumerate(scenario.obstacles):
        name = f"obstacle{index}"
        entities.add_scenario_object(name, obstacle_vehicle(box, name))
        init.add_init_action(name, xosc.TeleportAction(_world(*obstacle_reference_pose(box))))
    init.add_global_action(_light(scenario))
    story = xosc.Story("vrusim_story")
    story.add_act(act)
    storyboard = xosc.StoryBoard(init, _stop_trigger(scenario, params))
    storyboard.add_story(story)
    description = f"{scenario.name}: {scenario.description} " if scenario.description else f"{scenario.name}: "
    description += f"(exported by vrusim {__version__}; the test setup, the planner's reaction is not included)"
    return xosc.Scenario(
        description,
        "vrusim",
        params.declarations,
        entities,
        storyboard,
        xosc.RoadNetwork(roadfile=road_file),
        xosc.Catalog(),
        header_properties=notes,
    )


DRAWN_ROAD_NOTE = (
    "road.lines and road.surfaces (an imported road, drawn only) are not exported; the road is the layout's"
)
"""Header property `vrusim_road` of the export of a scenario with a drawn road."""


def opendrive_document(scenario: Scenario) -> xodr.OpenDrive:
    """The OpenDRIVE road of a scenario (see `interop.opendrive`): always its `layout`. A drawn road
    (`road.lines`, `road.surfaces`, e.g. of an imported network) is not written back: it holds polylines, not
    an OpenDRIVE network; the header property `vrusim_road` says so."""
    return road_network(scenario.road, road_half_length_m(scenario), file_stem(scenario.name))


@dataclass(frozen=True)
class OpenScenarioExport:
    """A scenario's OpenSCENARIO and OpenDRIVE documents, built in memory, to be written as `STEM.xosc/.xodr`."""

    stem: str
    scenario_doc: xosc.Scenario
    road_doc: xodr.OpenDrive

    def write(self, out_dir: Path) -> list[Path]:
        """Write both files into `out_dir` as one unit (both or neither); return their paths."""
        xosc_path, xodr_path = Path(out_dir) / f"{self.stem}.xosc", Path(out_dir) / f"{self.stem}.xodr"
        return write_together(
            [
                (xosc_path, lambda path: self.scenario_doc.write_xml(str(path)), "OpenSCENARIO file"),
                (xodr_path, lambda path: self.road_doc.write_xml(str(path)), "OpenDRIVE file"),
            ]
        )


def build_export(scenario: Scenario, stem: str | None = None) -> OpenScenarioExport:
    """Both documents of a scenario (stem: from its name); the .xosc references the .xodr by its file name."""
    stem = stem or file_stem(scenario.name)
    return OpenScenarioExport(stem, openscenario_document(scenario, f"{stem}.xodr"), opendrive_document(scenario))


def export_openscenario(scenario: Scenario, out_dir: Path, stem: str | None = None) -> list[Path]:
    """Write `STEM.xosc` and `STEM.xodr` (stem: from the scenario name) into `out_dir`; return their paths."""
    return build_export(scenario, stem).write(out_dir)
