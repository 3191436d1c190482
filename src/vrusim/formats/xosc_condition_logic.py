"""Map the conditions of `xosc_condition_kinds` onto vrusim triggers, beside `xosc_triggers.TriggerMapper`.

- ParameterCondition: "always" -> t = 0; "never" -> the OR-ed group drops out (a trigger that never holds is
  refused). VariableCondition -> t = 0, the start of the event whose VariableAction makes it true, or a time
  (`xosc_variables`).
- Speed, StandStill and RelativeSpeed conditions: on an entity whose speed is known before the run (a VRU started
  at a time, an obstacle; relative to one) -> the time they first hold (`xosc_speed_conditions`); on the ego
  (relative to an entity whose speed is constant until the trigger: an obstacle, the started VRU itself) ->
  `ego_speed_below_mps` / `ego_speed_above_mps` / `ego_standstill_s`, evaluated during the run.
- TimeToCollision to an entity standing until the trigger, or to a position, from the ego's reference point
  (freespace false) on its straight route -> `ego_time_to_arrival_s` to the point moved ahead by the ego's
  rear-axle-to-front length (distance from the reference point = distance from the front to that point).
- AND-ed conditions (`AllCondition`): the latest time, or route station, checked to hold together there; the
  lowest / highest speed of one kind; mixed kinds are refused.
- conditionEdge falling: a time `lessThan` -> that time; a distance on the ego's route -> the station where the
  ego leaves it; a speed known before the run -> the time it stops holding; an ego speed condition that holds
  at t = 0 -> the opposite speed trigger.
- CollisionCondition as a start condition is refused: a run stops at first contact (`sim.stop_on_collision`)
  and VRUs do not react to a contact.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

from vrusim.errors import UserInputError
from vrusim.formats.xosc_condition_kinds import (
    NEGATED,
    AllCondition,
    FallingCondition,
    SpeedTest,
    VariableChange,
    VariableTest,
    compare,
)
from vrusim.formats.xosc_expression import Value
from vrusim.formats.xosc_model import AnyCondition, Condition, PlaceCondition, WorldPose
from vrusim.formats.xosc_speed_conditions import Profile, difference, first_time, standstill_time
from vrusim.formats.xosc_triggers import ON_LINE_M, Fail, TriggerMapper, first_station
from vrusim.formats.xosc_variables import variable_start
from vrusim.scenario.routes import ego_route_spec

NEW_KINDS = {"always", "never", "all", "falling", "speed", "standstill", "variable", "collision"}
_FLIPPED = {
    "greaterThan": "lessThan",
    "greaterOrEqual": "lessOrEqual",
    "lessThan": "greaterThan",
    "lessOrEqual": "greaterOrEqual",
    "equalTo": "equalTo",
    "notEqualTo": "notEqualTo",
}
"""The rule of `b rule' a` equivalent to `a rule b`."""
_EGO_SPEED_KINDS = ("ego_speed_below_mps", "ego_speed_above_mps", "ego_standstill_s")
Trigger = dict[str, Any]


def _new(condition: Condition) -> bool:
    """Whether `condition` needs this module (else `TriggerMapper` maps it as before)."""
    if isinstance(condition, AnyCondition):
        return any(_new(option) for option in condition.options)
    if isinstance(condition, PlaceCondition) and condition.kind == "ttc":
        return bool(condition.other) or not condition.freespace
    return condition.kind in NEW_KINDS


class ConditionMapper(TriggerMapper):
    """`TriggerMapper` with variables, speed conditions, AND-ed groups and falling edges."""

    def __init__(
        self,
        fail: Fail,
        ego_name: str,
        events: dict[str, Condition],
        standing: dict[str, WorldPose],
        vrus: set[str],
        variables: dict[str, Value | str],
        changes: list[VariableChange],
        profile: Callable[[str], Profile | None],
        initial_speed: dict[str, float],
    ) -> None:
        """`variables`: declared values; `changes`: the events' VariableActions; `profile(entity)`: its speed
        profile when known before the run (None: the ego, or a VRU started by the run); `initial_speed`: each
        entity's speed at t = 0, m/s."""
        super().__init__(fail, ego_name, events, standing, vrus)
        self.variables, self.changes, self.profile, self.initial_speed = variables, changes, profile, initial_speed

    # ------------------------------------------------------------------------------------------- resolving

    def resolve(self, condition: Condition, depth: int = 0) -> Condition:
        if isinstance(condition, VariableTest):
            return self.resolve(self.variable(condition), depth + 1)
        if isinstance(condition, AllCondition):
            options = tuple(self.resolve(option, depth) for option in condition.options)
            return AllCondition("all", line=condition.line, options=options)
        if isinstance(condition, FallingCondition):
            return FallingCondition("falling", line=condition.line, inner=self.resolve(condition.inner, depth))
        if condition.kind == "event_start" and condition.ref in self.events and depth <= 16:
            base = self.resolve(self.events[condition.ref], depth + 1)
            if base.kind == "always":
                return Condition("time", condition.delay_s, line=condition.line)
            if base.kind == "never":
                return base
        return super().resolve(condition, depth)

    def variable(self, test: VariableTest) -> Condition:
        def event_time(event: str) -> float | None:
            start = self.resolve(self.events[event]) if event in self.events else None
            if start is not None and start.kind == "always":
                return 0.0
            return start.value if start is not None and start.kind == "time" else None

        def refuse(message: str) -> UserInputError:
            return self.refuse(test, message)

        return variable_start(test, self.variables[test.ref], self.changes, event_time, refuse)

    # ------------------------------------------------------------------------------------------- VRU triggers

    def vru_trigger(self, condition: Condition, vru: str) -> Trigger:
        resolved = self.resolve(condition)
        if not _new(resolved):
            return super().vru_trigger(condition, vru)
        return self.mapped(resolved, vru)

    def phase_start(self, condition: Condition) -> tuple[str, float]:
        resolved = self.resolve(condition)
        if not _new(resolved):
            return super().phase_start(condition)
        trigger = self.mapped(resolved, "")
        key = next(iter(trigger))
        if key not in ("at_time_s", "ego_route_m"):
            raise self.refuse(
                resolved, "an ego speed change starts at a time or on its route distance, not on its own speed"
            )
        return key, float(trigger[key])

    def mapped(self, condition: Condition, vru: str) -> Trigger:
        """The trigger of a resolved condition (`vru`: the VRU it starts, "" for a driver phase)."""
        if isinstance(condition, AnyCondition):
            options = [o for o in condition.options if o.kind != "never"]
            if not options:
                raise self.refuse(condition, "never holds (every group is false)")
            if any(o.kind == "always" for o in options):
                return {"at_time_s": 0.0}
            return self.earliest([self.mapped(o, vru) for o in options], condition.line)
        if condition.kind == "always":
            return {"at_time_s": 0.0}
        if condition.kind == "never":
            raise self.refuse(condition, "never holds, so the event would never start")
        if condition.kind == "collision":
            raise self.refuse(
                condition,
                "cannot start an event: a run stops at first contact (sim.stop_on_collision) and VRUs "
                "do not react to a contact",
            )
        if isinstance(condition, AllCondition):
            return self.all_of(condition, vru)
        if isinstance(condition, FallingCondition):
            return self.falling(condition, vru)
        if isinstance(condition, SpeedTest):
            return self.speed(condition, vru)
        if isinstance(condition, PlaceCondition) and condition.kind == "ttc":
            return self.time_to_collision(condition, vru)
        if condition.kind == "time":
            return {"at_time_s": condition.value}
        return super().vru_trigger(condition, vru)

    # ------------------------------------------------------------------------------------------- speeds

    def speed_of(self, name: str, vru: str) -> Profile | None:
        """The speed profile of entity `name` until VRU `vru` starts (None: the ego)."""
        if name == self.ego_name:
            return None
        if name == vru or name not in self.initial_speed:
            return ((0.0, self.initial_speed.get(name, 0.0)),)
        return self.profile(name)

    def speed(self, condition: SpeedTest, vru: str) -> Trigger:
        ego = self.ego_name
        if condition.kind == "standstill":
            if condition.ref == ego:
                return self.undelayed(condition, {"ego_standstill_s": condition.value})
            return self.at_time(condition, standstill_time(self.known(condition, condition.ref, vru), condition.value))
        mine = self.speed_of(condition.ref, vru)
        other = self.speed_of(condition.other, vru) if condition.other else ((0.0, 0.0),)
        if mine is not None and other is not None:
            profile = difference(mine, other)
            return self.at_time(condition, first_time(profile, condition.rule, condition.value))
        if mine is None and other is not None and len(other) == 1:
            return self.undelayed(condition, self.ego_speed(condition, condition.rule, condition.value + other[0][1]))
        if other is None and mine is not None and len(mine) == 1:
            rule = _FLIPPED[condition.rule]
            return self.undelayed(condition, self.ego_speed(condition, rule, mine[0][1] - condition.value))
        raise self.refuse(condition, "the speed of the ego relative to a moving entity is not supported")

    def known(self, condition: Condition, name: str, vru: str) -> Profile:
        profile = self.speed_of(name, vru)
        if profile is None:
            raise self.refuse(condition, f"the speed of {name!r} is not known before the run")
        return profile

    def at_time(self, condition: Condition, time_s: float | None) -> Trigger:
        if time_s is None:
            raise self.refuse(condition, "never holds, so the event would never start")
        return {"at_time_s": time_s + condition.delay_s}

    def undelayed(self, condition: Condition, trigger: Trigger) -> Trigger:
        if condition.delay_s != 0.0 and next(iter(trigger)) in _EGO_SPEED_KINDS:
            raise self.refuse(condition, "a delay is not supported on a condition on the ego's speed")
        return trigger

    def ego_speed(self, condition: Condition, rule: str, threshold: float) -> Trigger:
        """The run-time trigger for `ego speed rule threshold` (m/s; the ego drives forward)."""
        if self.ego is None or self.ego.reverse:
            raise self.refuse(condition, "a condition on the ego's speed needs the ego driving forward")
        if rule in ("equalTo", "notEqualTo"):
            raise self.refuse(condition, f"rule {rule} on the ego's speed holds for an instant: not supported")
        strict = rule in ("greaterThan", "lessThan")
        if abs(threshold) < 1e-12 and strict and rule == "greaterThan":
            raise self.refuse(condition, "rule greaterThan 0 on the ego's speed: use greaterOrEqual with a value > 0")
        if rule.startswith("greater"):
            return {"at_time_s": 0.0} if threshold <= 0.0 else {"ego_speed_above_mps": threshold}
        if threshold < 0.0 or (threshold == 0.0 and strict):
            raise self.refuse(condition, "never holds: the ego's speed is never below 0")
        return {"ego_speed_below_mps": threshold}

    def ego_start_speed(self) -> float:
        assert self.ego is not None
        initial = self.ego.initial_speed_mps
        return initial if initial is not None else self.ego.cruise_speed_mps

    # ------------------------------------------------------------------------------------------- time to collision

    def time_to_collision(self, condition: PlaceCondition, vru: str) -> Trigger:
        """From the ego's reference point (freespace false) to a position or a standing entity; or freespace
        true to a position (`TriggerMapper.time_to_arrival`)."""
        if condition.freespace:
            if condition.other or condition.ref != self.ego_name:
                raise self.refuse(condition, "a freespace time to collision is supported to a <Position> only")
            return self.time_to_arrival(condition)
        ego = self.known_ego(condition)
        if condition.delay_s != 0.0:
            raise self.refuse(condition, "a delayed time to collision is not supported")
        px, py = self.point(condition, vru)
        spec = ego_route_spec(ego)
        heading = spec.heading0_rad
        dx, dy = px - spec.x0_m, py - spec.y0_m
        along = math.cos(heading) * dx + math.sin(heading) * dy
        across = -math.sin(heading) * dx + math.cos(heading) * dy
        front = ego.length_m - ego.rear_overhang_m
        if ego.route.kind != "straight" or abs(across) > ON_LINE_M or along < front:
            raise self.refuse(condition, "a time to collision needs a point ahead of the ego on its straight route")
        point = {"x_m": px + front * math.cos(heading), "y_m": py + front * math.sin(heading)}
        return {"ego_time_to_arrival_s": condition.value, "point": point}

    # ------------------------------------------------------------------------------------------- AND, falling

    def all_of(self, condition: AllCondition, vru: str) -> Trigger:
        """AND-ed conditions: every one holds at the returned instant (else refused)."""
        options = [o for o in condition.options if o.kind != "always"]
        never = [o for o in options if o.kind == "never"]
        if never:
            raise self.refuse(never[0], "never holds, so its AND-ed <ConditionGroup> never holds")
        if not options:
            return {"at_time_s": 0.0}
        if len(options) > 1 and any(isinstance(o, FallingCondition) for o in options):
            raise self.refuse(condition, "a falling edge AND-ed with another condition is not supported")
        triggers = [self.mapped(o, vru) for o in options]
        kinds = {next(iter(t)) for t in triggers}
        if len(kinds) != 1:
            raise self.refuse(
                condition, f"AND-ed conditions of different kinds ({', '.join(sorted(kinds))}) are not supported"
            )
        key = kinds.pop()
        values = [float(t[key]) for t in triggers]
        if key in ("ego_speed_below_mps",):
            return {key: min(values)}
        if key in ("ego_speed_above_mps", "ego_standstill_s"):
            return {key: max(values)}
        if key not in ("at_time_s", "ego_route_m"):
            raise self.refuse(condition, f"AND-ed {key} conditions are not supported")
        latest = max(values)
        for option in options:
            if not self.lasts(option, key, latest, vru):
                raise self.refuse(condition, "its conditions do not hold together when the last of them first holds")
        return {key: latest}

    def lasts(self, option: Condition, key: str, at: float, vru: str) -> bool:
        """Whether `option`, once it holds, still holds at time (or route station) `at`."""
        if option.kind in ("time", "travel"):
            return True
        if isinstance(option, PlaceCondition) and option.kind == "distance" and key == "ego_route_m":
            leave = self.leave(option, vru, self.approach(option, vru))
            return leave is None or leave > at
        if (
            isinstance(option, SpeedTest)
            and key == "at_time_s"
            and option.kind == "speed"
            and option.ref != self.ego_name
        ):
            mine = self.known(option, option.ref, vru)
            other = self.known(option, option.other, vru) if option.other else ((0.0, 0.0),)
            profile = difference(mine, other)
            start = first_time(profile, option.rule, option.value)
            end = first_time(profile, NEGATED[option.rule], option.value, start) if start is not None else None
            return end is None or end > at - option.delay_s + 1e-12 or end == start == at
        return False

    def falling(self, condition: FallingCondition, vru: str) -> Trigger:
        inner = condition.inner
        if inner.kind == "time_before":
            return {"at_time_s": inner.value}
        if isinstance(inner, PlaceCondition) and inner.kind == "distance" and inner.delay_s == 0.0:
            leave = self.leave(inner, vru, self.approach(inner, vru))
            if leave is None:
                raise self.refuse(
                    inner, "the ego does not leave this distance along its route: the falling edge never comes"
                )
            return {"ego_route_m": leave}
        if isinstance(inner, SpeedTest) and inner.kind == "speed":
            mine, other = (
                self.speed_of(inner.ref, vru),
                self.speed_of(inner.other, vru) if inner.other else ((0.0, 0.0),),
            )
            if mine is not None and other is not None:
                profile = difference(mine, other)
                start = first_time(profile, inner.rule, inner.value)
                end = first_time(profile, NEGATED[inner.rule], inner.value, start) if start is not None else None
                return self.at_time(inner, end)
            if inner.ref == self.ego_name and not inner.other and inner.delay_s == 0.0 and self.ego is not None:
                if not compare(self.ego_start_speed(), inner.rule, inner.value):
                    raise self.refuse(inner, "a falling edge of an ego speed condition needs it to hold at t = 0")
                return self.ego_speed(inner, NEGATED[inner.rule], inner.value)
        if inner.kind == "never":
            raise self.refuse(inner, "never holds, so it never falls")
        raise self.refuse(
            inner,
            "with conditionEdge falling is not supported: it never stops holding, or not at a moment known "
            "before the run",
        )

    def leave(self, condition: PlaceCondition, vru: str, entry_m: float) -> float | None:
        """The first route station after `entry_m` where the ego is farther than `condition.value` from the
        point (None: it stays within to the route's end)."""
        distance = self.route_distance(condition, vru)
        return first_station(lambda s: distance(s) > condition.value, entry_m, self.known_ego(condition).route.length_m)
