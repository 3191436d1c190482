"""`<TimeReference><Timing domainAbsoluteRelative scale offset>` of a FollowTrajectoryAction: when the entity must
reach each vertex, and the vrusim fields that reproduce it.

A time as written, t, becomes the simulation time t * scale + offset (ASAM OpenSCENARIO XML 1.3, "Timing";
scale > 0). `absolute` and `relative` (to the action's start) read alike: vrusim starts trajectories at t = 0.
Every vertex needs a time (`<Vertex time>`; a clothoid's `startTime` / `stopTime`; a spline's segment `timeStart`
and `timeEnd`).

vrusim moves along a path at one speed, so timing maps only where it is a constant speed: v = path length /
(last time - first time), and every vertex reached within `TIME_TOL_S` of the first time + its distance along the
path / v. A VRU then stands at its start until the first time and moves at v (`trigger.at_time_s`,
`top_speed_mps`, a step acceleration); the ego's timing must be its cruise speed from t = 0. Anything else is
refused, naming the first vertex off its time.
"""

from __future__ import annotations

import itertools
import math
from typing import Any

from vrusim.errors import UserInputError
from vrusim.formats.xml_file import Element
from vrusim.formats.xosc_document import XoscDocument
from vrusim.formats.xosc_model import STEP_RATE_MPS2, SampledShape, VertexTimes, WorldPose

TIME_TOL_S = 0.01
"""Largest difference between a vertex's time and the constant-speed time, s."""


def read_timing(doc: XoscDocument, time_reference: Element) -> tuple[float, float] | None:
    """(scale, offset s) of a `<TimeReference>`, None for `<None/>`."""
    timing = doc.single(time_reference, {"None", "Timing"})
    if timing.tag == "None":
        return None
    doc.children(timing, set())
    doc.choice(timing, "domainAbsoluteRelative", ("absolute", "relative"))
    scale = doc.number(timing, "scale")
    if not scale > 0:
        raise doc.fail(timing, f"attribute scale: must be > 0, got {scale:g}")
    return scale, doc.number(timing, "offset")


def vertex_times(doc: XoscDocument, shape: SampledShape, timing: tuple[float, float] | None) -> VertexTimes | None:
    """The simulation times of the vertices of `shape`, or None without timing; a vertex without a time is an
    error naming its element."""
    if timing is None:
        return None
    scale, offset = timing
    for time, (tag, line) in zip(shape.times_s, shape.sources, strict=True):
        if time is None:
            raise UserInputError(f"{doc.source}: line {line}: <{tag}> has no time, which <Timing> needs")
    times = tuple(float(t) * scale + offset for t in shape.times_s if t is not None)
    return VertexTimes(times, tuple(shape.sources))


def _fail(source: str, timing: VertexTimes, index: int, message: str) -> UserInputError:
    tag, line = timing.sources[index]
    return UserInputError(f"{source}: line {line}: <{tag}> {message}")


def constant_speed(source: str, vertices: tuple[WorldPose, ...], timing: VertexTimes) -> tuple[float, float]:
    """(first time s, speed m/s) of a timed trajectory moving at one speed; else an error naming the vertex."""
    along = [
        0.0,
        *itertools.accumulate(math.dist((a.x_m, a.y_m), (b.x_m, b.y_m)) for a, b in itertools.pairwise(vertices)),
    ]
    times = timing.times_s
    if times[-1] <= times[0]:
        raise _fail(source, timing, len(times) - 1, f"time {times[-1]:g} s is not after the first ({times[0]:g} s)")
    speed = along[-1] / (times[-1] - times[0])
    if not speed > 0:
        raise _fail(source, timing, len(times) - 1, "ends where the trajectory starts: a timed trajectory must move")
    for index, (distance, time) in enumerate(zip(along, times, strict=True)):
        expected = times[0] + distance / speed
        if abs(time - expected) > TIME_TOL_S:
            raise _fail(
                source,
                timing,
                index,
                f"is timed {time:g} s, but at one speed ({speed:.4g} m/s) it is reached at {expected:.4g} s: "
                "vrusim moves along a trajectory at one constant speed",
            )
    return times[0], speed


def timed_vru_fields(
    source: str, vertices: tuple[WorldPose, ...], timing: VertexTimes, initial_mps: float
) -> dict[str, Any]:
    """The VRU fields of a timed trajectory: stand until the first time, then move at one speed."""
    first, speed = constant_speed(source, vertices, timing)
    if first < 0:
        raise _fail(source, timing, 0, f"is timed {first:g} s: a trajectory's first vertex must be at t >= 0")
    if first > 0 and initial_mps != 0.0:
        raise _fail(source, timing, 0, f"is timed {first:g} s, but the entity moves before it (initial speed)")
    return {
        "initial_speed_mps": speed if first == 0 else 0.0,
        "top_speed_mps": speed,
        "max_accel_mps2": STEP_RATE_MPS2,
        "trigger": {"at_time_s": first},
    }


def check_ego_timing(source: str, vertices: tuple[WorldPose, ...], timing: VertexTimes, cruise_mps: float) -> None:
    """Refuse an ego trajectory timing that is not its cruise speed from t = 0."""
    first, speed = constant_speed(source, vertices, timing)
    if abs(first) > TIME_TOL_S:
        raise _fail(source, timing, 0, f"is timed {first:g} s, but the ego drives its route from t = 0")
    along = sum(math.dist((a.x_m, a.y_m), (b.x_m, b.y_m)) for a, b in itertools.pairwise(vertices))
    if abs(along / cruise_mps - along / speed if cruise_mps > 0 else math.inf) > TIME_TOL_S:
        raise _fail(
            source,
            timing,
            len(vertices) - 1,
            f"is timed for {speed:.4g} m/s, but the ego's cruise speed is {cruise_mps:.4g} m/s",
        )
