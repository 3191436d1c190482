"""Trajectory shapes `<Clothoid>` and `<ClothoidSpline>` (ASAM OpenSCENARIO XML 1.3) sampled into vertices.

A clothoid starts at its `<Position>` (the entity's `<Init>` pose when absent) with curvature `curvature` (1/m,
positive turns left), which changes by `curvaturePrime` (1.2+; `curvatureDot` before, the same quantity in 1/m^2)
per metre over `length` m. A spline is a chain of `<ClothoidSplineSegment curvatureStart curvatureEnd length
hOffset>`: a segment starts at its `<PositionStart>` when given, else where the previous one ends (the first:
at the entity's pose), turned by `hOffset` (rad); a `<PositionStart>` away from the previous end is refused
(vrusim paths do not jump). Times (with `<Timing>` only): `startTime` / `stopTime` of a clothoid, each
segment's `timeStart` and the spline's `timeEnd`, linear in arc length in between (a constant speed per piece).

Vertices are exact poses on the curve (`geometry.paths.path_poses`, Gauss-Legendre to round-off) at most
`SPACING_M` apart, so the end pose is exact; a straight run-out of `OVERRUN_M` follows the end (the ego's
route fit drops it; a VRU walks on along the end tangent, as past any last waypoint).
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np

from vrusim.formats.xml_file import Element
from vrusim.formats.xodr_model import Network
from vrusim.formats.xosc_document import XoscDocument
from vrusim.formats.xosc_model import OVERRUN_M, SampledShape, WorldPose
from vrusim.formats.xosc_positions import read_position
from vrusim.geometry.paths import SAMPLE_SPACING_M, Clothoid, PathSpec, path_poses
from vrusim.limits import check_limit

SPACING_M = SAMPLE_SPACING_M
"""Largest distance along the curve between two vertices, m."""
JOIN_M = 1e-3
"""A segment's `<PositionStart>` must lie this close to the end of the previous segment, m."""


def clothoid_poses(start: WorldPose, k_start: float, k_end: float, length_m: float) -> list[WorldPose]:
    """Poses along a clothoid from `start` (curvature k_start to k_end 1/m over length_m m), at most `SPACING_M`
    apart, both ends included."""
    count = max(2, math.ceil(length_m / SPACING_M - 1e-9) + 1)
    stations = np.linspace(0.0, length_m, count)
    spec = PathSpec(start.x_m, start.y_m, start.heading_rad, (Clothoid(k_start, k_end, length_m),))
    x, y, heading, _ = path_poses(spec, stations)
    return [WorldPose(float(a), float(b), float(h)) for a, b, h in zip(x, y, heading, strict=True)]


def _times(start_s: float | None, end_s: float | None, count: int) -> list[float | None]:
    if start_s is None or end_s is None:
        return [None] * count
    return [float(t) for t in np.linspace(start_s, end_s, count)]


def _optional_number(doc: XoscDocument, element: Element, name: str) -> float | None:
    return doc.number(element, name) if name in element.attrib else None


def _length(doc: XoscDocument, element: Element, before_m: float = 0.0) -> float:
    """The `length` attribute (> 0); with the `before_m` of the pieces before it, within the `length_m` limit of a
    path's length (checked before the curve is sampled every `SPACING_M`)."""
    length = doc.number(element, "length")
    if not length > 0:
        raise doc.fail(element, f"attribute length: must be > 0, got {length:g}")
    what = "attribute length" if before_m == 0 else "attribute length (with the segments before it)"
    check_limit("length_m", before_m + length, f"{doc.source}: line {element.line}: <{element.tag}> {what}")
    return length


def _own_pose(doc: XoscDocument, element: Element, own: WorldPose | None) -> WorldPose:
    if own is None:
        raise doc.fail(element, "has no start position and its entity has no TeleportAction in <Init> before it")
    return own


def with_run_out(shape: SampledShape) -> SampledShape:
    """`shape` with a straight `OVERRUN_M` past its last vertex along its heading (time: at the last speed)."""
    end, previous = shape.vertices[-1], shape.vertices[-2]
    shape.vertices.append(
        WorldPose(
            end.x_m + OVERRUN_M * math.cos(end.heading_rad),
            end.y_m + OVERRUN_M * math.sin(end.heading_rad),
            end.heading_rad,
        )
    )
    t_end, t_previous = shape.times_s[-1], shape.times_s[-2]
    step = math.dist((end.x_m, end.y_m), (previous.x_m, previous.y_m))
    extra = None
    if t_end is not None and t_previous is not None and t_end > t_previous:
        extra = t_end + OVERRUN_M * (t_end - t_previous) / step
    shape.times_s.append(extra)
    shape.sources.append(shape.sources[-1])
    shape.run_out = True
    return shape


def read_clothoid(
    doc: XoscDocument,
    element: Element,
    network: Network,
    placed: Mapping[str, WorldPose] | None,
    own: WorldPose | None,
) -> SampledShape:
    """The vertices of a `<Clothoid>` (see the module docstring)."""
    doc.children(element, {"Position"})
    given = [name for name in ("curvaturePrime", "curvatureDot") if name in element.attrib]
    if len(given) != 1:
        raise doc.fail(element, "needs exactly one of the attributes curvaturePrime and curvatureDot")
    k0, rate, length = doc.number(element, "curvature"), doc.number(element, given[0]), _length(doc, element)
    position = doc.optional(element, "Position")
    start = read_position(doc, position, network, placed) if position is not None else _own_pose(doc, element, own)
    poses = clothoid_poses(start, k0, k0 + rate * length, length)
    times = _times(_optional_number(doc, element, "startTime"), _optional_number(doc, element, "stopTime"), len(poses))
    return with_run_out(SampledShape(poses, times, [(element.tag, element.line)] * len(poses)))


def read_clothoid_spline(
    doc: XoscDocument,
    element: Element,
    network: Network,
    placed: Mapping[str, WorldPose] | None,
    own: WorldPose | None,
) -> SampledShape:
    """The vertices of a `<ClothoidSpline>` (see the module docstring)."""
    segments = doc.children(element, {"ClothoidSplineSegment"})
    if not segments:
        raise doc.fail(element, "needs at least one <ClothoidSplineSegment>")
    shape = SampledShape()
    total_m = 0.0
    starts = [_optional_number(doc, segment, "timeStart") for segment in segments]
    ends = [*starts[1:], _optional_number(doc, element, "timeEnd")]
    for segment, t_start, t_end in zip(segments, starts, ends, strict=True):
        doc.children(segment, {"PositionStart"})
        holder = doc.optional(segment, "PositionStart")
        previous = shape.vertices[-1] if shape.vertices else None
        if holder is not None:
            start = read_position(doc, holder, network, placed)
            if previous is not None and math.dist((start.x_m, start.y_m), (previous.x_m, previous.y_m)) > JOIN_M:
                raise doc.fail(holder, "lies away from the end of the previous segment: a vrusim path cannot jump")
        else:
            start = previous if previous is not None else _own_pose(doc, segment, own)
        start = WorldPose(start.x_m, start.y_m, start.heading_rad + doc.number(segment, "hOffset", 0.0))
        k0, k1, length = (
            doc.number(segment, "curvatureStart"),
            doc.number(segment, "curvatureEnd"),
            _length(doc, segment, total_m),
        )
        total_m += length
        poses = clothoid_poses(start, k0, k1, length)
        times = _times(t_start, t_end, len(poses))
        if shape.vertices:  # the joint: the previous end's position, this segment's heading and time
            shape.vertices.pop()
            shape.times_s.pop()
            shape.sources.pop()
        shape.vertices += poses
        shape.times_s += times
        shape.sources += [(segment.tag, segment.line)] * len(poses)
    return with_run_out(shape)
