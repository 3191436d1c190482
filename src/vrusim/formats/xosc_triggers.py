"""Map imported start conditions onto vrusim's triggers: a VRU's `trigger` and a driver phase's start.

- a simulation time (+ delay) -> `at_time_s`; the ego's travelled distance -> `ego_route_m`;
- the ego within a distance of a point (ReachPosition, Distance, RelativeDistance to an entity standing until
  then; from the ego's reference point, or with `freespace` from its bounding box) -> `ego_route_m`: the first
  route station (rear axle, m) where it holds, solved on the ego's route (the ego drives its route);
- a time to collision with a point on the ego's straight route ahead of it, freespace -> `ego_time_to_arrival_s`;
- an event's start (+ delay) -> that event's condition (a delay only after a time);
- OR-ed groups -> the earliest of their times, or of their route stations.

Everything else is refused, naming the condition's line: vrusim has no trigger that fires exactly then.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from vrusim.errors import UserInputError
from vrusim.formats.xosc_model import AnyCondition, Condition, PlaceCondition, WorldPose
from vrusim.geometry.paths import path_poses
from vrusim.scenario.routes import ego_route_spec
from vrusim.scenario.schema import Ego

SEARCH_STEP_M = 0.01
"""Spacing of the route stations searched for where a distance condition first holds, m (then bisected)."""
MAX_SEARCH_POINTS = 200_001
"""At most this many stations are searched (a route longer than 2 km is searched more coarsely)."""
ON_LINE_M = 1e-3
"""A time-to-collision point is on the ego's straight route when within this distance of its line, m."""
_MAX_CHAIN = 16
_TAGS = {
    "time": "SimulationTimeCondition",
    "travel": "TraveledDistanceCondition",
    "event_start": "StoryboardElementStateCondition",
    "collision": "CollisionCondition",
    "any": "StartTrigger",
}

Fail = Callable[[int, str], UserInputError]


class TriggerMapper:
    """Maps conditions for one scenario: the ego (None until known), the standing entities' reference points."""

    def __init__(
        self, fail: Fail, ego_name: str, events: dict[str, Condition], standing: dict[str, WorldPose], vrus: set[str]
    ) -> None:
        """`standing`: reference points of the obstacles and of the VRUs standing until their trigger (`vrus`:
        the VRU names; a VRU's own point only counts for its own trigger)."""
        self.fail, self.ego_name, self.events, self.standing, self.vrus = fail, ego_name, events, standing, vrus
        self.ego: Ego | None = None

    def refuse(self, condition: Condition, message: str) -> UserInputError:
        """An error at `condition`'s line, naming its element."""
        tag = getattr(condition, "tag", "") or _TAGS.get(condition.kind, "Condition")
        return self.fail(condition.line, f"<{tag}> {message}")

    # ------------------------------------------------------------------------------------------- events

    def resolve(self, condition: Condition, depth: int = 0) -> Condition:
        """`condition` with event starts replaced by the started event's condition (delays added to times)."""
        if isinstance(condition, AnyCondition):
            options = tuple(self.resolve(option, depth) for option in condition.options)
            return AnyCondition("any", line=condition.line, options=options)
        if condition.kind != "event_start":
            return condition
        if depth > _MAX_CHAIN:
            raise self.refuse(condition, "event start conditions refer to each other in a loop")
        event = self.events.get(condition.ref)
        if event is None:
            raise self.refuse(condition, f"names no speed-change event: {condition.ref!r}")
        base = self.resolve(event, depth + 1)
        if condition.delay_s == 0.0:
            return base
        if base.kind == "time":
            return Condition("time", base.value + condition.delay_s, line=condition.line)
        raise self.refuse(condition, "a delayed event start is supported only after an event started at a time")

    # ------------------------------------------------------------------------------------------- VRU triggers

    def vru_trigger(self, condition: Condition, vru: str) -> dict[str, object]:
        """The `trigger` mapping of VRU `vru` for its start condition (`vru` is in `standing` when it stands until
        then)."""
        resolved = self.resolve(condition)
        if isinstance(resolved, AnyCondition):
            return self.earliest([self.vru_trigger(option, vru) for option in resolved.options], resolved.line)
        if resolved.kind == "time":
            return {"at_time_s": resolved.value}
        if resolved.delay_s != 0.0:
            raise self.refuse(resolved, f"a delayed {resolved.kind} condition is not supported (only a time's)")
        if resolved.kind == "travel" and resolved.ref == self.ego_name:
            return {"ego_route_m": resolved.value}
        if isinstance(resolved, PlaceCondition) and resolved.kind == "distance":
            return {"ego_route_m": self.approach(resolved, vru)}
        if isinstance(resolved, PlaceCondition) and resolved.kind == "ttc":
            return self.time_to_arrival(resolved)
        raise self.refuse(
            resolved,
            "a VRU starts at a time, on the ego's travelled distance, distance to a point or time to collision",
        )

    def earliest(self, triggers: list[dict[str, object]], line: int) -> dict[str, object]:
        """OR-ed triggers: the earliest time or route station (all of one kind), else refused."""
        kinds = {next(iter(t)) for t in triggers}
        if kinds == {"at_time_s"} or kinds == {"ego_route_m"}:
            key = kinds.pop()
            return {key: min(float(t[key]) for t in triggers)}  # type: ignore[arg-type]
        if all(t == triggers[0] for t in triggers):
            return triggers[0]
        raise self.fail(line, "<StartTrigger> OR-ed groups must all be times or all the ego's route distances")

    # ------------------------------------------------------------------------------------------- driver phases

    def phase_start(self, condition: Condition) -> tuple[str, float]:
        """("at_time_s" or "ego_route_m", value) of a driver phase started by `condition`."""
        resolved = self.resolve(condition)
        if isinstance(resolved, AnyCondition):
            found = self.earliest([dict([self.phase_start(o)]) for o in resolved.options], resolved.line)
            key = next(iter(found))
            return key, float(found[key])  # type: ignore[arg-type]
        if resolved.kind == "time":
            return "at_time_s", resolved.value
        if resolved.delay_s != 0.0:
            raise self.refuse(resolved, f"a delayed {resolved.kind} condition is not supported (only a time's)")
        if resolved.kind == "travel" and resolved.ref == self.ego_name:
            return "ego_route_m", resolved.value
        if isinstance(resolved, PlaceCondition) and resolved.kind == "distance":
            return "ego_route_m", self.approach(resolved, "")
        raise self.refuse(
            resolved, "an ego speed change starts at a time, on its travelled distance or near a position"
        )

    # ------------------------------------------------------------------------------------------- geometry

    def point(self, condition: PlaceCondition, vru: str) -> tuple[float, float]:
        """The fixed point the ego approaches: the condition's position or a standing entity's reference point."""
        other = condition.other
        if condition.ref != self.ego_name:
            if other != self.ego_name:
                raise self.refuse(condition, "only the ego's distance to a point or entity can start a VRU")
            other = condition.ref
        if not other:
            return condition.x_m, condition.y_m
        if condition.freespace:
            raise self.refuse(condition, "a freespace distance between two entities is not supported")
        pose = self.standing.get(other)
        if pose is None or (other in self.vrus and other != vru):
            raise self.refuse(condition, f"entity {other!r} moves before the trigger: its distance is not fixed")
        return pose.x_m, pose.y_m

    def known_ego(self, condition: Condition) -> Ego:
        if self.ego is None or self.ego.reverse:
            raise self.refuse(condition, "a distance or time-to-collision condition needs the ego driving forward")
        return self.ego

    def approach(self, condition: PlaceCondition, vru: str) -> float:
        """The first station of the ego's route (rear axle, m) where it is within `condition.value` of the point."""
        distance = self.route_distance(condition, vru)
        station = first_station(lambda s: distance(s) <= condition.value, 0.0, self.known_ego(condition).route.length_m)
        if station is None:
            raise self.refuse(condition, f"the ego never comes within {condition.value:g} m along its route")
        return station

    def route_distance(self, condition: PlaceCondition, vru: str) -> Callable[[np.ndarray], np.ndarray]:
        """The ego's distance to the condition's point at stations of its route (m -> m): from its reference point
        (rear axle), or with `freespace` from its bounding box."""
        ego = self.known_ego(condition)
        px, py = self.point(condition, vru)
        spec = ego_route_spec(ego)
        front, back, half = ego.length_m - ego.rear_overhang_m, -ego.rear_overhang_m, ego.width_m / 2

        def distance(stations: np.ndarray) -> np.ndarray:
            x, y, heading, _ = path_poses(spec, stations)
            dx, dy = px - x, py - y
            if not condition.freespace:
                return np.hypot(dx, dy)
            along = np.cos(heading) * dx + np.sin(heading) * dy
            across = np.abs(-np.sin(heading) * dx + np.cos(heading) * dy)
            out_x = np.maximum(np.maximum(along - front, back - along), 0.0)
            return np.hypot(out_x, np.maximum(across - half, 0.0))

        return distance

    def time_to_arrival(self, condition: PlaceCondition) -> dict[str, object]:
        """`ego_time_to_arrival_s` to a point on the ego's straight route ahead, measured from its front."""
        ego = self.known_ego(condition)
        if not condition.freespace or condition.other:
            raise self.refuse(condition, "a time to collision is supported to a <Position> with freespace true")
        spec = ego_route_spec(ego)
        dx, dy = condition.x_m - spec.x0_m, condition.y_m - spec.y0_m
        along = math.cos(spec.heading0_rad) * dx + math.sin(spec.heading0_rad) * dy
        across = -math.sin(spec.heading0_rad) * dx + math.cos(spec.heading0_rad) * dy
        front = ego.length_m - ego.rear_overhang_m
        if ego.route.kind != "straight" or abs(across) > ON_LINE_M or along < front:
            raise self.refuse(condition, "a time to collision needs a point ahead of the ego on its straight route")
        return {"ego_time_to_arrival_s": condition.value, "point": {"x_m": condition.x_m, "y_m": condition.y_m}}


def first_station(holds: Callable[[np.ndarray], np.ndarray], start_m: float, end_m: float) -> float | None:
    """The first station in [start_m, end_m] where `holds` (stations -> bools) is true: found on a grid of
    `SEARCH_STEP_M` (at most `MAX_SEARCH_POINTS` points), then bisected (None: it never holds there)."""
    count = min(MAX_SEARCH_POINTS, max(2, math.ceil((end_m - start_m) / SEARCH_STEP_M) + 1))
    stations = np.linspace(start_m, end_m, count)
    found = np.nonzero(holds(stations))[0]
    if found.size == 0:
        return None
    if found[0] == 0:
        return start_m
    low, high = float(stations[found[0] - 1]), float(stations[found[0]])
    for _ in range(50):
        middle = (low + high) / 2
        if holds(np.array([middle]))[0]:
            high = middle
        else:
            low = middle
    return high
