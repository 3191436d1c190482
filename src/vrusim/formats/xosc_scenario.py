"""Build a vrusim scenario mapping from what an OpenSCENARIO file says (entities, storyboard, road).

The ego: the entity named `ego` or `VUT` (any case), else the first vehicle that is not a bicycle or motorbike.
VRUs: pedestrians, bicycles (cyclist; `vrusim:type` e_scooter kept) and motorbikes (motorcyclist). Every other
vehicle and every misc object is a parked obstacle; it must not move. The mapping of each element to a
scenario field is in docs/openscenario_import.md.
"""

from __future__ import annotations

import itertools
import math
from typing import Any

from vrusim.errors import UserInputError
from vrusim.formats.xosc_document import XoscDocument
from vrusim.formats.xosc_model import OVERRUN_M, Condition, EntityDef, Motion, SpeedChange, StoryDef, WorldPose
from vrusim.formats.xosc_route_fit import fit_route
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


class ScenarioBuilder:
    """Turns entities + storyboard into a scenario mapping; errors name the file and the element's line."""

    def __init__(self, doc: XoscDocument, entities: list[EntityDef], story: StoryDef) -> None:
        self.doc, self.entities, self.story = doc, entities, story
        ego = choose_ego(entities)
        if ego is None:
            raise self.error(0, "has no ego: name an entity 'ego' or 'VUT', or give a car")
        self.ego = ego

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
        if len(motion.speed_changes) > 1:
            raise self.error(motion.speed_changes[1].line, "the ego may change its speed once (to its cruise speed)")
        for change in motion.speed_changes:
            self.at_start(change.condition, "the ego's speed change")
            cruise = abs(change.target_mps)
            fields |= {"cruise_speed_mps": cruise, "initial_speed_mps": abs(initial)}
            if change.rate_mps2 is not None:
                fields["max_accel_mps2" if cruise > abs(initial) else "max_decel_mps2"] = change.rate_mps2
        return fields

    def at_start(self, condition: Condition, what: str) -> None:
        if (condition.kind, condition.value) != ("time", 0.0):
            raise self.error(condition.line, f"{what} must start at simulation time 0")

    # ------------------------------------------------------------------------------------------- VRUs

    def trigger(self, condition: Condition) -> dict[str, float]:
        if condition.kind == "time":
            return {"at_time_s": condition.value}
        if condition.kind == "travel" and condition.ref == self.ego.name:
            return {"ego_route_m": condition.value}
        raise self.error(condition.line, "a VRU starts at a simulation time or when the ego has travelled a distance")

    def vru_speeds(self, entity: EntityDef, motion: Motion, initial: float) -> dict[str, Any]:
        changes = list(motion.speed_changes)
        starts = [c for c in changes if c.condition.kind != "event_start"]
        brakes = [c for c in changes if c.condition.kind == "event_start"]
        if len(starts) > 1 or len(brakes) > 1:
            raise self.error(changes[-1].line, f"entity {entity.name!r}: a VRU starts once and brakes at most once")
        if not starts:
            if brakes:
                raise self.error(brakes[0].line, f"entity {entity.name!r}: a brake event needs a start event")
            accel = {"max_accel_mps2": entity.max_accel_mps2} if entity.max_accel_mps2 else {}
            return {"top_speed_mps": initial} | accel
        start = starts[0]
        fields = {
            "top_speed_mps": _rate_needed(self, start).target_mps,
            "max_accel_mps2": start.rate_mps2,
            "trigger": self.trigger(start.condition),
        }
        if brakes:
            brake = _rate_needed(self, brakes[0])
            if brake.condition.ref != start.event or brake.target_mps != 0.0:
                raise self.error(brake.line, f"entity {entity.name!r}: a brake is a stop to 0 after the start event")
            fields["brake"] = {"after_trigger_s": brake.condition.delay_s, "decel_mps2": brake.rate_mps2}
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
            "radius_m": float(radius) if radius is not None else max(entity.length_m, entity.width_m) / 2,
        }
        fields |= self.vru_speeds(entity, motion, fields["initial_speed_mps"])
        trajectory = motion.trajectory
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
            elif condition.kind == "event_start" or (condition.kind == "travel" and condition.ref != self.ego.name):
                raise self.error(condition.line, "the stop trigger may be a time, the ego's travel or a collision")
        return fields

    def mapping(self) -> dict[str, Any]:
        """The scenario mapping without name, description and road."""
        vrus, obstacles = [], []
        for entity in self.entities:
            if entity is self.ego:
                continue
            kind = vru_type(entity)
            if kind is not None:
                vrus.append(self.vru_fields(entity, kind))
            else:
                obstacles.append(self.obstacle_fields(entity))
        data: dict[str, Any] = {
            "ego": self.ego_fields(),
            "vrus": vrus,
            "obstacles": obstacles,
            "sim": self.sim_fields(),
        }
        if self.story.night is not None:
            data["sensor"] = {"lighting": "night" if self.story.night else "day"}
        return data


def _rate_needed(builder: ScenarioBuilder, change: SpeedChange) -> SpeedChange:
    if change.rate_mps2 is None:
        raise builder.error(change.line, "a VRU's speed change must be linear at a rate (dynamicsDimension rate)")
    return change


def _length(vertices: tuple[WorldPose, ...]) -> float:
    return sum(math.dist((a.x_m, a.y_m), (b.x_m, b.y_m)) for a, b in itertools.pairwise(vertices))


def _continues(a: WorldPose, b: WorldPose, c: WorldPose) -> bool:
    """Whether segment b -> c goes on in the direction of a -> b."""
    first = math.atan2(b.y_m - a.y_m, b.x_m - a.x_m)
    second = math.atan2(c.y_m - b.y_m, c.x_m - b.x_m)
    return abs(math.remainder(second - first, math.tau)) < COLLINEAR_RAD
