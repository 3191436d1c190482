"""Map a VRU's `<SynchronizeAction>` (master: the ego) onto its speed profile and trigger, computed at import.

The ego drives its nominal motion (`xosc_ego_nominal`: the `none` planner's); T is the time from the action's
start until the ego's reference point (rear axle) reaches TargetPositionMaster (its route station, found as for a
ReachPositionCondition: the first station within `targetToleranceMaster`; with tolerance 0 the projection of a
point within `ON_PATH_M` of the route), d the VRU's way from where it is then to TargetPosition along its path
(likewise with `targetTolerance`). `xosc_sync_profile` solves the profile; the action's start condition is the
VRU's trigger (a time or the ego's route distance), moved later when the VRU first holds its speed.

The profile is fixed once the action starts: a VUT that brakes does not make the VRU slow down or wait (the Euro
NCAP intent). Refused, naming the element and its line: a master other than the ego, a synchronised entity that
is not a VRU, other speed changes of a synchronised VRU, targets off the route or path, an ego whose speed changes
without a driver schedule or that reverses, a start condition other than a time or the ego's route distance (and
a later start only after a time), and profiles vrusim's VRU cannot follow (`xosc_sync_profile`).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from vrusim.errors import UserInputError
from vrusim.formats.xosc_ego_nominal import EgoNominal
from vrusim.formats.xosc_model import EntityDef, Motion, PlaceCondition, Synchronize
from vrusim.formats.xosc_sync_profile import ON_PATH_M, ProfileError, path_station, solve_profile
from vrusim.formats.xosc_triggers import TriggerMapper
from vrusim.geometry.paths import path_poses
from vrusim.scenario.routes import ego_route_spec
from vrusim.scenario.schema import Ego

Fail = Callable[[int, str], UserInputError]
_TAG = "<SynchronizeAction>"


def check_sync_actors(fail: Fail, motions: dict[str, Motion], vrus: set[str]) -> None:
    """Refuse a SynchronizeAction of an entity that is not a VRU (the ego, an obstacle)."""
    for name, motion in motions.items():
        if motion.sync is not None and name not in vrus:
            raise fail(
                motion.sync.line,
                f"{_TAG} entity {name!r} is not a VRU: only a VRU can be synchronised (with the ego as master)",
            )


def synchronised_vru(
    fail: Fail, triggers: TriggerMapper, entity: EntityDef, motion: Motion, vru_fields: Callable[[], dict[str, Any]]
) -> dict[str, Any]:
    """The scenario fields of VRU `entity` whose motion has a sync: `vru_fields()` with its profile and trigger."""
    sync = motion.sync
    assert sync is not None
    if sync.master != triggers.ego_name:
        raise fail(sync.line, f"{_TAG} masterEntityRef {sync.master!r}: only the ego can be the master")
    if motion.speed_changes:
        change = motion.speed_changes[0]
        raise fail(
            change.line,
            f"<LongitudinalAction> entity {entity.name!r} is synchronised (line {sync.line}): vrusim's VRU follows "
            "one speed profile, so a synchronised VRU has no other speed change",
        )
    ego = triggers.ego
    assert ego is not None
    nominal = _nominal(fail, ego, sync)
    fields = vru_fields()
    master_s, master_mps = _arrival(fail, nominal, _master_station(fail, triggers, ego, sync), sync)
    trigger = triggers.vru_trigger(sync.condition, entity.name)
    start_s = _start_time(fail, nominal, trigger, sync)
    v0 = fields["initial_speed_mps"]
    target_m = _target_station(fail, fields, entity, sync)
    way_m, time_s = target_m - v0 * start_s, master_s - start_s
    if way_m <= 0.0:
        raise fail(
            sync.target_line, f"<TargetPosition> the VRU has passed it when the action starts (t = {start_s:.3f} s)"
        )
    if time_s <= 0.0:
        raise fail(
            sync.master_line,
            f"<TargetPositionMaster> the ego reaches it at t = {master_s:.3f} s, not after the action starts "
            f"(t = {start_s:.3f} s)",
        )
    final_mps, steady_m = _final(fail, sync, master_mps)
    try:
        profile = solve_profile(v0, way_m, time_s, final_mps, steady_m)
    except ProfileError as error:
        raise fail(sync.final.line if sync.final else sync.line, f"{_element(sync)} {error}") from None
    if profile.delay_s > 0.0:
        if "at_time_s" not in trigger:
            raise fail(
                sync.line,
                f"{_TAG} the VRU must hold its speed {profile.delay_s:.3f} s after the action starts; vrusim delays "
                "a start only when it starts at a simulation time",
            )
        trigger = {"at_time_s": start_s + profile.delay_s}
    fields |= {"trigger": trigger, "top_speed_mps": profile.top_mps}
    if profile.rate_mps2 is not None:
        _within_performance(fail, entity, profile.rate_mps2, profile.top_mps > v0, sync)
        fields["max_accel_mps2"] = profile.rate_mps2
    return fields


def _element(sync: Synchronize) -> str:
    return "<FinalSpeed>" if sync.final is not None else _TAG


def _nominal(fail: Fail, ego: Ego, sync: Synchronize) -> EgoNominal:
    if ego.reverse:
        raise fail(sync.line, f"{_TAG} needs the ego driving forward")
    if ego.driver is None and abs(ego.start_speed_mps - ego.cruise_speed_mps) > 1e-9:
        raise fail(
            sync.line,
            f"{_TAG} the ego's speed must be constant or a driver schedule (its speed change at t = 0 depends on "
            "the planner)",
        )
    return EgoNominal(ego)


def _master_station(fail: Fail, triggers: TriggerMapper, ego: Ego, sync: Synchronize) -> float:
    """The ego's route station (rear axle, m) where it reaches TargetPositionMaster."""
    point = sync.master_target
    tolerance = sync.master_tolerance_m
    condition = PlaceCondition(
        "distance",
        value=max(tolerance, ON_PATH_M),
        ref=triggers.ego_name,
        line=sync.master_line,
        x_m=point.x_m,
        y_m=point.y_m,
        tag="TargetPositionMaster",
    )
    first = triggers.approach(condition, "")
    if tolerance >= ON_PATH_M:
        return first
    spec = ego_route_spec(ego)

    def distance(station: float) -> float:
        x, y, _, _ = path_poses(spec, np.array([station]))
        return math.hypot(point.x_m - x[0], point.y_m - y[0])

    low, high = first, first + 2.0 * ON_PATH_M
    for _ in range(60):  # the closest station: the point's projection onto the route
        a, b = low + (high - low) / 3.0, high - (high - low) / 3.0
        low, high = (low, b) if distance(a) <= distance(b) else (a, high)
    return 0.5 * (low + high)


def _arrival(fail: Fail, nominal: EgoNominal, station_m: float, sync: Synchronize) -> tuple[float, float]:
    arrival = nominal.time_at_station(station_m)
    if arrival is None:
        raise fail(sync.master_line, "<TargetPositionMaster> the ego stops before it (its nominal speed schedule)")
    return arrival


def _start_time(fail: Fail, nominal: EgoNominal, trigger: dict[str, Any], sync: Synchronize) -> float:
    """When the action starts on the nominal motion, s."""
    if "at_time_s" in trigger:
        return float(trigger["at_time_s"])
    if "ego_route_m" in trigger:
        reached = nominal.time_at_station(float(trigger["ego_route_m"]))
        if reached is not None:
            return reached[0]
        raise fail(sync.condition.line, "<StartTrigger> the ego stops before this synchronisation starts")
    raise fail(
        sync.condition.line,
        f"{_TAG} must start at a simulation time or on the ego's route distance (not a time to arrival)",
    )


def _target_station(fail: Fail, fields: dict[str, Any], entity: EntityDef, sync: Synchronize) -> float:
    """The VRU's path station (of its box centre, m) where its reference point reaches TargetPosition."""
    start = (fields["start"]["x_m"], fields["start"]["y_m"])
    if "path" in fields:
        points = [(p["x_m"], p["y_m"]) for p in fields["path"]]
    else:
        heading = math.radians(fields["heading_deg"])
        points = [(start[0] + math.cos(heading), start[1] + math.sin(heading))]
    target = (sync.target.x_m, sync.target.y_m)
    station = path_station(start, points, target, sync.tolerance_m)
    if station is None:
        within = max(sync.tolerance_m, ON_PATH_M)
        raise fail(sync.target_line, f"<TargetPosition> is not within {within:g} m of the VRU's path ahead of it")
    return station + entity.centre_x_m


def _final(fail: Fail, sync: Synchronize, ego_mps: float) -> tuple[float | None, float | None]:
    """(final speed m/s or None, steady-state distance m or None); `ego_mps`: the ego's speed at its target."""
    final = sync.final
    if final is None:
        return None, None
    if final.kind == "absolute":
        speed = final.value
    else:
        speed = ego_mps + final.value if final.kind == "delta" else ego_mps * final.value
        if speed < 0.0:
            raise fail(final.line, f"<FinalSpeed> the final speed relative to the ego's ({ego_mps:g} m/s) is below 0")
    steady = final.steady_m if final.steady_s is None else final.steady_s * speed
    return speed, steady


def _within_performance(fail: Fail, entity: EntityDef, rate: float, faster: bool, sync: Synchronize) -> None:
    limit = entity.max_accel_mps2 if faster else entity.max_decel_mps2
    if limit is not None and rate > limit + 1e-9:
        which = "maxAcceleration" if faster else "maxDeceleration"
        raise fail(
            sync.line,
            f"{_TAG} needs {rate:.3f} m/s^2, above entity {entity.name!r}'s <Performance> {which} {limit:g}",
        )
