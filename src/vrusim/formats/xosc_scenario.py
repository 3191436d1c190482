"""Build a vrusim scenario mapping from what an OpenSCENARIO file says (entities, storyboard, road).

The ego: the entity named `ego` or `VUT` (any case), else the first vehicle that is not a bicycle or motorbike.
VRUs: pedestrians, bicycles (cyclist; `vrusim:type` e_scooter kept) and motorbikes (motorcyclist). Every other
vehicle and every misc object is a parked obstacle; it must not move. The mapping of each element to a
scenario field is in docs/openscenario_import.md.
"""

from __future__ import annotations

import functools
import itertools
import math
from typing import Any

from pydantic import ValidationError

from vrusim.errors import UserInputError
from vrusim.formats.xosc_condition_logic import ConditionMapper
from vrusim.formats.xosc_document import XoscDocument
from vrusim.formats.xosc_longitudinal import place_entities
from vrusim.formats.xosc_model import (
    OVERRUN_M,
    STEP_RATE_MPS2,
    Condition,
    EntityDef,
    Motion,
    RampedSpeedChange,
    SpeedChange,
    StoryDef,
    WorldPose,
)
from vrusim.formats.xosc_route_fit import fit_route
from vrusim.formats.xosc_speed_conditions import STANDING, Profile, vru_profile
from vrusim.formats.xosc_speed_shapes import refuse_shaped_ego, vru_speed_shape
from vrusim.formats.xosc_sync_vru import check_sync_actors, synchronised_vru
from vrusim.formats.xosc_timing import check_ego_timing, timed_vru_fields
from vrusim.formats.xosc_variables import declared_values
from vrusim.scenario.loading import describe_validation_error
from vrusim.scenario.schema import Ego
from vrusim.scenario.vru_types import VruType

EGO_NAMES = ("ego", "vut")
VRU_CATEGORIES = {"pedestrian": VruType.PEDESTRIAN, "bicycle": VruType.CYCLIST, "motorbike": VruType.MOTORCYCLIST}
"""VRU type of a Pedestrian's or Vehicle's category (a `vrusim:type` property overrides it)."""
COLLINEAR_RAD = 1e-6
"""A VRU path's last vertex is dropped when it continues the previous segment within this angle (the export's
straight run-out: vrusim VRUs keep walking straight past their last waypoint)."""


def choose_ego(entities: list[EntityDef]) -> EntityDef | None:
    """The ego by the rule above, or None."""
    named = [e for e in entities if e.name.lower() in EGO_NAMES]
    if named:
        return named[0]
    return next((e for e in entities if e.kind == "vehicle" and e.category not in VRU_CATEGORIES), None)


def vru_type(entity: EntityDef) -> VruType | None:
    """The VRU type of an entity, or None when it is not a VRU."""
    base = VRU_CATEGORIES.get(entity.category) if entity.kind != "misc" else None
    given = entity.properties.get("vrusim:type")
    if base is not None and given in {t.value for t in VruType}:
        return VruType(given)
    return base


def _ahead(pose: WorldPose, distance_m: float) -> dict[str, float]:
    """The pose moved `distance_m` along its heading, as a vrusim Pose mapping (heading in deg)."""
    return {
        "x_m": pose.x_m + distance_m * math.cos(pose.heading_rad),
        "y_m": pose.y_m + distance_m * math.sin(pose.heading_rad),
        "heading_deg": math.degrees(pose.heading_rad),
    }


def _number_property(source: str, entity: EntityDef, name: str, text: str) -> float:
    """A numeric `<Property>` of an entity (its value a number; finiteness is checked by the scenario model)."""
    try:
        return float(text)
    except ValueError:
        raise UserInputError(
            f"{source}: entity {entity.name!r}: property {name}: expected a number, got {text[:40]!r}"
        ) from None


class ScenarioBuilder:
    """Turns entities + storyboard into a scenario mapping; errors name the file and the element's line."""

    def __init__(self, doc: XoscDocument, entities: list[EntityDef], story: StoryDef) -> None:
        self.doc, self.entities, self.story = doc, entities, story
        place_entities(self.error, entities, story)
        ego = choose_ego(entities)
        if ego is None:
            raise self.error(0, "has no ego: name an entity 'ego' or 'VUT', or give a car")
        self.ego = ego
        events = {c.event: c.condition for m in story.motions.values() for c in m.speed_changes} | story.events
        standing, vrus = {}, set()
        for entity in entities:
            motion = story.motions[entity.name]
            if entity is not ego and vru_type(entity) is not None:
                vrus.add(entity.name)
            if entity is not ego and not motion.initial_speed_mps and motion.pose is not None:
                standing[entity.name] = motion.pose
        initial = {e.name: self.story.motions[e.name].initial_speed_mps or 0.0 for e in entities if e is not ego}
        variables = declared_values(doc)
        changes = story.variable_changes
        self.profiling: set[str] = set()
        self.triggers = ConditionMapper(
            self.error, ego.name, events, standing, vrus, variables, changes, self.speed_profile, initial
        )

    def speed_profile(self, name: str) -> Profile | None:
        """The speed profile of entity `name` when known before the run (a VRU started at a time, an obstacle)."""
        entity = next(e for e in self.entities if e.name == name)
        kind = vru_type(entity)
        if kind is None:
            return STANDING
        if name in self.profiling:
            raise self.error(entity.line, f"entity {name!r}: its start depends on its own speed")
        self.profiling.add(name)
        try:
            motion = self.story.motions[name]
            initial = motion.initial_speed_mps or 0.0
            return vru_profile({"initial_speed_mps": initial} | self.vru_speeds(entity, motion, initial))
        finally:
            self.profiling.discard(name)

    def error(self, line: int, message: str) -> UserInputError:
        where = f"line {line}: " if line else ""
        return UserInputError(f"{self.doc.source}: {where}{message}")

    def pose(self, entity: EntityDef) -> WorldPose:
        pose = self.story.motions[entity.name].pose
        if pose is None:
            raise self.error(entity.line, f"entity {entity.name!r} has no TeleportAction in <Init>")
        return pose

    # ------------------------------------------------------------------------------------------- the ego

    def stop_length_m(self) -> float | None:
        lengths = [c.value for c in self.story.stop if c.kind == "travel" and c.ref == self.ego.name]
        return lengths[0] if lengths else None

    def ego_route(self, motion: Motion, pose: WorldPose, reverse: bool) -> dict[str, Any]:
        trajectory = motion.trajectory
        if trajectory is None:
            raise self.error(self.ego.line, f"the ego {self.ego.name!r} follows no trajectory")
        self.at_start(trajectory.condition, "the ego's trajectory")
        vertices = trajectory.vertices

        def fail(message: str) -> Exception:
            return self.error(trajectory.line, f"the ego's trajectory {message}")

        if reverse:
            end = vertices[-1]
            if len(vertices) != 2 or abs(trajectory.offset_m - _length(vertices)) > 1e-6:
                raise fail("must be one straight line followed from its end when the ego reverses")
            if math.hypot(end.x_m - pose.x_m, end.y_m - pose.y_m) > 1e-3:
                raise fail("must end at the ego's position when it reverses")
            length = self.stop_length_m()
            return {"kind": "straight", "length_m": length if length is not None else _length(vertices) - OVERRUN_M}
        if trajectory.offset_m != 0.0:
            raise fail("must be followed from its start (initialDistanceOffset 0) when the ego drives forward")
        start = vertices[0]
        if math.hypot(start.x_m - pose.x_m, start.y_m - pose.y_m) > 1e-3:
            raise fail("must start at the ego's position")
        return fit_route(vertices, self.stop_length_m(), fail)

    def ego_fields(self) -> dict[str, Any]:
        ego, motion = self.ego, self.story.motions[self.ego.name]
        if ego.kind != "vehicle":
            raise self.error(ego.line, f"the ego {ego.name!r} must be a <Vehicle>")
        pose = self.pose(ego)
        refuse_shaped_ego(motion.speed_changes, self.error)
        initial = motion.initial_speed_mps or 0.0
        reverse = initial < 0 or any(c.target_mps < 0 for c in motion.speed_changes)
        fields: dict[str, Any] = {
            "start": _ahead(pose, ego.centre_x_m),
            "length_m": ego.length_m,
            "width_m": ego.width_m,
            "wheelbase_m": ego.wheelbase_m,
            "rear_overhang_m": ego.length_m / 2 - ego.centre_x_m,
            "max_steer_deg": math.degrees(ego.max_steer_rad or 0.0),
            "max_accel_mps2": ego.max_accel_mps2,
            "max_decel_mps2": ego.max_decel_mps2,
            "reverse": reverse,
            "route": self.ego_route(motion, pose, reverse),
            "cruise_speed_mps": abs(initial),
        }
        changes = motion.speed_changes
        if reverse or (len(changes) == 1 and self.starts_at_zero(changes[0].condition)):
            if len(changes) > 1:
                raise self.error(changes[1].line, "a reversing ego may change its speed once (to its cruise speed)")
            for change in changes:
                self.at_start(change.condition, "the ego's speed change")
                cruise = abs(change.target_mps)
                fields |= {"cruise_speed_mps": cruise, "initial_speed_mps": abs(initial)}
                rate = _rate(change, abs(initial))
                if rate is not None:
                    fields["max_accel_mps2" if cruise > abs(initial) else "max_decel_mps2"] = rate
            return fields
        if changes:
            fields["driver"] = self.driver(changes, initial, fields)
        self.ego_timing(motion, fields)
        return fields

    def ego_timing(self, motion: Motion, fields: dict[str, Any]) -> None:
        """Refuse a timed ego trajectory unless it is driven at the cruise speed from t = 0 (xosc_timing)."""
        trajectory = motion.trajectory
        if trajectory is None or trajectory.timing is None:
            return
        if (
            fields["reverse"]
            or "driver" in fields
            or fields.get("initial_speed_mps") not in (None, fields["cruise_speed_mps"])
        ):
            raise self.error(trajectory.line, "a timed ego trajectory needs one constant speed (no speed changes)")
        check_ego_timing(self.doc.source, trajectory.vertices, trajectory.timing, fields["cruise_speed_mps"])

    def driver(self, changes: list[SpeedChange], initial: float, fields: dict[str, Any]) -> dict[str, Any]:
        """The ego's speed changes as driver phases (the first holds the initial speed from t = 0; a step at t = 0
        is the initial speed). Sets `cruise_speed_mps` to the initial speed."""
        limits = {key: fields[key] or Ego.model_fields[key].default for key in ("max_accel_mps2", "max_decel_mps2")}
        starts = sorted(((self.triggers.phase_start(c.condition), c) for c in changes), key=lambda s: s[0][1])
        while starts and starts[0][0] == ("at_time_s", 0.0) and _rate(starts[0][1], initial) is None:
            initial = starts.pop(0)[1].target_mps
        fields["cruise_speed_mps"] = initial
        first = {"at_time_s": 0.0, "target_speed_mps": initial, "accel_mps2": limits["max_accel_mps2"]}
        phases = [first | {"accelerator": initial > 0}]
        if len({kind for (kind, _), _ in starts}) > 1:
            raise self.error(changes[0].line, "the ego's speed changes must all start at times or all on distances")
        speed, done = initial, 0.0
        for index, ((kind, value), change) in enumerate(starts):
            target = change.target_mps
            if value < done - 1e-9:
                raise self.error(*_dynamics(change, "the ego's speed change starts before the previous one has ended"))
            rate = _rate(change, speed) if target != speed else limits["max_accel_mps2"]
            if rate is None:
                raise self.error(*_dynamics(change, "the ego cannot change its speed in a step: give a linear one"))
            limit = "max_accel_mps2" if target > speed else "max_decel_mps2"
            if rate > limits[limit] + 1e-9:
                message = f"rate {rate:g} m/s^2 exceeds the ego's {limit} {limits[limit]:g}"
                raise self.error(*_dynamics(change, message))
            if kind == "at_time_s":
                done = value + abs(target - speed) / rate
            elif target == 0.0 and index + 1 < len(starts):
                raise self.error(starts[index + 1][1].line, "the ego stops before this speed change's distance")
            else:
                done = value + abs(target * target - speed * speed) / (2.0 * rate)
            phases.append({kind: value, "target_speed_mps": target, "accel_mps2": rate, "accelerator": target > 0})
            speed = target
        return {"phases": phases}

    def starts_at_zero(self, condition: Condition) -> bool:
        resolved = self.triggers.resolve(condition)
        return (resolved.kind, resolved.value) == ("time", 0.0)

    def at_start(self, condition: Condition, what: str) -> None:
        resolved = self.triggers.resolve(condition)
        if resolved.kind == "never":
            raise self.triggers.refuse(resolved, f"never holds, and {what} must start at simulation time 0")
        if resolved.kind != "always" and (resolved.kind, resolved.value) != ("time", 0.0):
            raise self.error(condition.line, f"{what} must start at simulation time 0")

    # ------------------------------------------------------------------------------------------- VRUs

    def vru_speeds(self, entity: EntityDef, motion: Motion, initial: float) -> dict[str, Any]:
        """Top speed, acceleration, trigger and brake of a VRU: a start event and at most one stop after it."""
        changes = list(motion.speed_changes)
        own = {c.event for c in changes}
        brakes = [c for c in changes if c.condition.kind == "event_start" and c.condition.ref in own]
        starts = [c for c in changes if c not in brakes]
        after = brakes[0].condition.delay_s if brakes else 0.0
        if len(starts) == 2 and not brakes:
            times = [self.triggers.resolve(c.condition) for c in starts]
            if all(t.kind == "time" for t in times):
                order = sorted(range(2), key=lambda i: times[i].value)
                starts, brakes = [starts[order[0]]], [starts[order[1]]]
                after = times[order[1]].value - times[order[0]].value
        if len(starts) > 1 or len(brakes) > 1:
            raise self.error(changes[-1].line, f"entity {entity.name!r}: a VRU starts once and brakes at most once")
        if not starts:
            if brakes:
                raise self.error(brakes[0].line, f"entity {entity.name!r}: a brake event needs a start event")
            accel = {"max_accel_mps2": entity.max_accel_mps2} if entity.max_accel_mps2 else {}
            return {"top_speed_mps": initial} | accel
        start = starts[0]
        top = start.target_mps
        accel = _rate(start, initial) if top != initial else None
        trigger = self.triggers.vru_trigger(start.condition, entity.name)
        fields: dict[str, Any] = {"top_speed_mps": top, "trigger": trigger}
        if top != initial:
            fields["max_accel_mps2"] = accel if accel is not None else STEP_RATE_MPS2
        elif isinstance(start, RampedSpeedChange) and start.ramp.dimension == "rate" and start.rate_mps2:
            fields["max_accel_mps2"] = start.rate_mps2
        if brakes:
            brake = brakes[0]
            if brake.target_mps != 0.0:
                raise self.error(brake.line, f"entity {entity.name!r}: a brake is a stop to 0 after the start event")
            ramping = top != initial and abs(top - initial) / fields["max_accel_mps2"] > after + 1e-9
            if ramping and isinstance(brake, RampedSpeedChange) and brake.ramp.dimension in ("time", "distance"):
                raise self.error(brake.line, f"entity {entity.name!r}: the stop starts before the top speed is reached")
            decel = _rate(brake, top) if top > 0 else None
            fields["brake"] = {"after_trigger_s": after, "decel_mps2": decel if decel is not None else STEP_RATE_MPS2}
        return fields

    def vru_fields(self, entity: EntityDef, kind: VruType) -> dict[str, Any]:
        motion = self.story.motions[entity.name]
        pose = self.pose(entity)
        start = _ahead(pose, entity.centre_x_m)
        radius = entity.properties.get("vrusim:radius_m")
        fields: dict[str, Any] = {
            "type": kind.value,
            "start": {"x_m": start["x_m"], "y_m": start["y_m"]},
            "initial_speed_mps": motion.initial_speed_mps or 0.0,
            "radius_m": _number_property(self.doc.source, entity, "vrusim:radius_m", radius)
            if radius is not None
            else max(entity.length_m, entity.width_m) / 2,
        }
        trajectory = motion.trajectory
        if trajectory is not None and trajectory.timing is not None:
            if motion.speed_changes:
                message = f"entity {entity.name!r}: a timed trajectory sets the speed; its speed events would too"
                raise self.error(motion.speed_changes[0].line, message)
            initial = fields["initial_speed_mps"]
            fields |= timed_vru_fields(self.doc.source, trajectory.vertices, trajectory.timing, initial)
        else:
            fields |= self.vru_speeds(entity, motion, fields["initial_speed_mps"])
        if trajectory is None:
            return fields | {"heading_deg": start["heading_deg"]}
        self.at_start(trajectory.condition, f"entity {entity.name!r}'s trajectory")
        vertices = list(trajectory.vertices)
        first = vertices[0]
        if trajectory.offset_m != 0.0 or math.hypot(first.x_m - start["x_m"], first.y_m - start["y_m"]) > 1e-3:
            raise self.error(trajectory.line, f"entity {entity.name!r}'s trajectory must start at its position")
        if len(vertices) == 2:
            end = vertices[1]
            return fields | {"heading_deg": math.degrees(math.atan2(end.y_m - first.y_m, end.x_m - first.x_m))}
        if _continues(vertices[-3], vertices[-2], vertices[-1]):
            vertices.pop()
        return fields | {"path": [{"x_m": v.x_m, "y_m": v.y_m} for v in vertices[1:]]}

    # ------------------------------------------------------------------------------------------- the rest

    def obstacle_fields(self, entity: EntityDef) -> dict[str, Any]:
        motion = self.story.motions[entity.name]
        if motion.trajectory is not None or motion.speed_changes or (motion.initial_speed_mps or 0.0) != 0.0:
            raise self.error(entity.line, f"entity {entity.name!r} moves: only the ego and VRUs may move")
        kind = entity.properties.get("vrusim:kind", entity.category)
        centre = _ahead(self.pose(entity), entity.centre_x_m)
        return {"kind": kind, "centre": centre, "length_m": entity.length_m, "width_m": entity.width_m}

    def sim_fields(self) -> dict[str, Any]:
        fields: dict[str, Any] = {
            "stop_on_collision": any(c.kind == "collision" for c in self.story.stop),
            "stop_at_route_end": self.stop_length_m() is not None,
        }
        for condition in self.story.stop:
            if condition.kind == "time":
                fields["duration_s"] = condition.value
            elif condition.kind == "collision" or (
                condition.kind == "travel" and condition.ref == self.ego.name and condition.delay_s == 0.0
            ):
                continue
            else:
                raise self.error(condition.line, "the stop trigger may be a time, the ego's travel or a collision")
        return fields

    def mapping(self) -> dict[str, Any]:
        """The scenario mapping without name, description and road."""
        ego = self.ego_fields()
        try:
            self.triggers.ego = Ego.model_validate(ego)
        except ValidationError as error:
            raise UserInputError(describe_validation_error(error, f"{self.doc.source}: ego")) from None
        vrus, obstacles, vru_changes = [], [], {}
        check_sync_actors(self.error, self.story.motions, self.triggers.vrus)
        for entity in self.entities:
            if entity is self.ego:
                continue
            kind = vru_type(entity)
            motion = self.story.motions[entity.name]
            if kind is not None and motion.sync is not None:
                make = functools.partial(self.vru_fields, entity, kind)
                vrus.append(synchronised_vru(self.error, self.triggers, entity, motion, make))
            elif kind is not None:
                vrus.append(self.vru_fields(entity, kind))
                vru_changes[entity.name] = motion.speed_changes
            else:
                obstacles.append(self.obstacle_fields(entity))
        shape = vru_speed_shape(vru_changes, self.error)
        if shape is not None:  # the VRU motion model of cubic or sinusoidal speed changes
            vrus = [vru | {"motion": shape} for vru in vrus]
        data: dict[str, Any] = {
            "ego": ego,
            "vrus": vrus,
            "obstacles": obstacles,
            "sim": self.sim_fields(),
        }
        if self.story.night is not None:
            data["sensor"] = {"lighting": "night" if self.story.night else "day"}
        return data


def _dynamics(change: SpeedChange, message: str) -> tuple[int, str]:
    """(line, message naming the element) of an error about a speed change's dynamics."""
    if isinstance(change, RampedSpeedChange) and change.ramp.line:
        return change.ramp.line, f"<SpeedActionDynamics> {message}"
    return change.line, f"<LongitudinalAction> {message}"


def _rate(change: SpeedChange, from_mps: float) -> float | None:
    """The constant rate of a speed change from `from_mps` (m/s^2); None: a step."""
    if isinstance(change, RampedSpeedChange):
        return change.ramp.rate_mps2(from_mps, change.target_mps)
    return change.rate_mps2


def _length(vertices: tuple[WorldPose, ...]) -> float:
    return sum(math.dist((a.x_m, a.y_m), (b.x_m, b.y_m)) for a, b in itertools.pairwise(vertices))


def _continues(a: WorldPose, b: WorldPose, c: WorldPose) -> bool:
    """Whether segment b -> c goes on in the direction of a -> b."""
    first = math.atan2(b.y_m - a.y_m, b.x_m - a.x_m)
    second = math.atan2(c.y_m - b.y_m, c.x_m - b.x_m)
    return abs(math.remainder(second - first, math.tau)) < COLLINEAR_RAD
