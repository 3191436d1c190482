"""Speed conditions: SpeedCondition, StandStillCondition, RelativeSpeedCondition read into `SpeedTest`s, and when
they first hold for an entity whose speed is known before the run (a piecewise-linear speed profile).

A VRU started at a simulation time moves open-loop: its initial speed until the trigger, then a constant-rate
change to its top speed, then (with a brake) a constant-rate stop; an obstacle stands. Their speeds are
`Profile`s: (time s, speed m/s) breakpoints, linear between them and constant after the last.
"""

from __future__ import annotations

import itertools
import math
from typing import Any

from vrusim.formats.xml_file import Element
from vrusim.formats.xosc_condition_kinds import RULES, SpeedTest, compare
from vrusim.formats.xosc_document import XoscDocument

Profile = tuple[tuple[float, float], ...]
STANDING: Profile = ((0.0, 0.0),)


def read_speed(doc: XoscDocument, element: Element, ref: str, delay_s: float) -> SpeedTest:
    """A SpeedCondition, StandStillCondition or RelativeSpeedCondition of entity `ref`."""
    doc.children(element, set())
    common: dict[str, Any] = {"ref": ref, "delay_s": delay_s, "line": element.line, "tag": element.tag}
    if element.tag == "StandStillCondition":
        duration = doc.number(element, "duration")
        if duration < 0:
            raise doc.fail(element, "attribute duration: must be >= 0")
        return SpeedTest("standstill", duration, **common)
    for name in ("direction", "directionalDimension"):
        if name in element.attrib:
            raise doc.fail(element, f"attribute {name}: a speed component is not supported (only the speed)")
    rule = doc.choice(element, "rule", RULES)
    other = doc.text(element, "entityRef") if element.tag == "RelativeSpeedCondition" else ""
    return SpeedTest("speed", doc.number(element, "value"), other=other, rule=rule, **common)


def vru_profile(fields: dict[str, Any]) -> Profile | None:
    """The speed profile of a VRU's scenario fields (`initial_speed_mps`, `top_speed_mps`, `max_accel_mps2`,
    `trigger`, `brake`); None when its trigger is not a simulation time (it depends on the run)."""
    trigger = fields.get("trigger", {"at_time_s": 0.0})
    if "at_time_s" not in trigger:
        return None
    start, v0 = float(trigger["at_time_s"]), float(fields["initial_speed_mps"])
    top = float(fields.get("top_speed_mps", v0))
    accel = float(fields.get("max_accel_mps2") or math.inf)
    points = [(0.0, v0), (start, v0)]
    reached = start + abs(top - v0) / accel
    brake = fields.get("brake")
    if brake is None:
        return (*points, (reached, top))
    braking = start + float(brake["after_trigger_s"])
    if braking < reached:  # the stop starts during the change: speed then
        top = v0 + (top - v0) * (braking - start) / (reached - start)
        reached = braking
    points += [(reached, top), (braking, top)]
    return (*points, (braking + top / float(brake["decel_mps2"]), 0.0))


def difference(a: Profile, b: Profile) -> Profile:
    """a - b, on the union of their breakpoints."""
    times = sorted({t for t, _ in a} | {t for t, _ in b})
    return tuple((t, at(a, t) - at(b, t)) for t in times)


def at(profile: Profile, t_s: float) -> float:
    """The profile's speed at `t_s`."""
    previous = profile[0]
    if t_s <= previous[0]:
        return previous[1]
    for point in profile[1:]:
        if t_s <= point[0]:
            t0, v0 = previous
            t1, v1 = point
            return v0 if t1 == t0 else v0 + (v1 - v0) * (t_s - t0) / (t1 - t0)
        previous = point
    return previous[1]


def _segments(profile: Profile, after_s: float) -> list[float]:
    """The breakpoint times from `after_s` on, ending with infinity (the last speed held)."""
    return [after_s, *(t for t, _ in profile if t > after_s), math.inf]


def first_time(profile: Profile, rule: str, value: float, after_s: float = 0.0) -> float | None:
    """The first instant from `after_s` on at which `speed rule value` holds (a strict rule crossed at t gives t,
    the start of the interval where it holds); None: never."""
    times = _segments(profile, after_s)
    for t0, t1 in itertools.pairwise(times):
        v0 = at(profile, t0)
        if compare(v0, rule, value):
            return t0
        v1 = at(profile, t1) if t1 < math.inf else v0
        if v1 == v0:
            continue
        crossing = t0 + (value - v0) / (v1 - v0) * (t1 - t0)
        if t0 <= crossing <= t1 and (
            compare(value, rule, value) or compare(at(profile, (crossing + t1) / 2), rule, value)
        ):
            return crossing
    return None


def standstill_time(profile: Profile, duration_s: float) -> float | None:
    """The first instant the speed has been 0 for `duration_s`; None: never."""
    times = _segments(profile, 0.0)
    stopped = None
    for t0, t1 in itertools.pairwise(times):
        v0 = at(profile, t0)
        v1 = at(profile, t1) if t1 < math.inf else v0
        if v0 == 0.0 and stopped is None:
            stopped = t0
        if v0 == 0.0 and v1 == 0.0:
            if t1 - stopped >= duration_s - 1e-12:  # type: ignore[operator]
                return stopped + duration_s  # type: ignore[operator]
            continue
        if stopped is not None and t0 - stopped >= duration_s - 1e-12:
            return stopped + duration_s
        stopped = None
    return None
