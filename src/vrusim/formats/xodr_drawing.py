"""Sample an OpenDRIVE network into the drawn road of a scenario: marked lines and paved surfaces (`road.lines`,
`road.surfaces`, `vrusim.scenario.road_lines`).

Every road (junction connecting roads included), lane section by lane section: the border at the lane offset,
and each lane's outer border (lanes narrower than 1 mm over the whole section are left out). A border is an
`edge` when it bounds the road or separates a carriageway lane from one that is not (sidewalk, shoulder,
border, ...), a `lane` boundary between two carriageway lanes on one side and the `centre` line between the two
innermost carriageway lanes of opposite sides. Its style comes from the `<roadMark type>` records of the lane
whose outer border it is (the centre lane's for the offset border): `none` is not drawn, types with a solid
line (solid, solid solid, solid broken, broken solid, curb, edge, grass, custom) are `solid`, broken,
broken broken and botts dots `broken`. Without a record: edges and the centre line solid, lane boundaries
broken. A surface is one section's outline: its outermost right border forward, its outermost left border back.

Each line is evaluated every `DENSE_SPACING_M` along s (exact points of the curve), then thinned by
Douglas-Peucker to within `SIMPLIFY_TOLERANCE_M`: every chord stays within 2 cm of the true curve (tolerance
plus the dense chords' sagitta of at most 1.25 mm / radius in m), and a straight line keeps its two ends.
Coordinates are rounded to 1 mm. Lengths in m.

Before anything is sampled, the points to evaluate are counted (`sample_count`, limit `road_samples`); a point
beyond `coordinate_m` is refused naming the `<geometry>` or `<lane>` that puts it there.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from vrusim.errors import UserInputError
from vrusim.formats.xodr_geometry import reference_poses
from vrusim.formats.xodr_lanes import cubic_at, lane_offset_m
from vrusim.formats.xodr_model import Lane, LaneSection, Network, Road, RoadMark
from vrusim.limits import LIMITS, amount, env_name, excess, limit

DENSE_SPACING_M = 0.1
"""Spacing of the exact points along s before thinning, m."""
SIMPLIFY_TOLERANCE_M = 0.015
"""Largest distance of a dropped point from the chord that replaces it, m."""
MIN_LANE_WIDTH_M = 1e-3
"""A lane narrower than this over a whole lane section draws no border of its own, m."""
ROUND_DECIMALS = 3
"""Coordinates are rounded to 1 mm."""

CARRIAGEWAY_TYPES = frozenset(
    {
        "driving",
        "bidirectional",
        "entry",
        "exit",
        "onRamp",
        "offRamp",
        "connectingRamp",
        "slipLane",
        "mwyEntry",
        "mwyExit",
        "bus",
        "taxi",
        "HOV",
    }
)
"""Lane types that carry motor traffic: the boundary between two of them is a lane line, not an edge."""
BROKEN_MARKS = frozenset({"broken", "broken broken", "botts dots"})
DEFAULT_STYLE = {"edge": "solid", "lane": "broken", "centre": "solid"}


@dataclass(frozen=True)
class _Border:
    """One border of a lane section: its t (m) at the section's stations, kind and road marks."""

    t_m: np.ndarray
    kind: str
    marks: tuple[RoadMark, ...]
    element: tuple[str, int] = ("laneSection", 0)
    """The element that places it, for messages: (tag, line)."""


def simplified(points: np.ndarray, tolerance_m: float = SIMPLIFY_TOLERANCE_M) -> np.ndarray:
    """The points [N, 2] kept by Douglas-Peucker (`kept_indices`)."""
    return points[kept_indices(points, tolerance_m)]


def kept_indices(points: np.ndarray, tolerance_m: float = SIMPLIFY_TOLERANCE_M) -> np.ndarray:
    """Indices (ascending) of the points [N, 2] Douglas-Peucker keeps: every dropped point lies within
    `tolerance_m` of the segment between the kept points around it; the ends are always kept."""
    count = len(points)
    keep = np.zeros(count, dtype=bool)
    keep[[0, count - 1]] = True
    stack = [(0, count - 1)]
    while stack:
        first, last = stack.pop()
        if last - first < 2:
            continue
        inner = points[first + 1 : last]
        start, end = points[first], points[last]
        chord = end - start
        length2 = float(chord @ chord)
        along = np.clip(((inner - start) @ chord) / length2, 0.0, 1.0) if length2 > 0 else np.zeros(len(inner))
        distance = np.hypot(*(inner - start - along[:, None] * chord).T)
        worst = int(np.argmax(distance))
        if distance[worst] > tolerance_m:
            middle = first + 1 + worst
            keep[middle] = True
            stack += [(first, middle), (middle, last)]
    return np.flatnonzero(keep)


def _rounded(points: np.ndarray) -> list[list[float]]:
    """Points rounded to 1 mm, without repeats, as [[x, y], ...]."""
    rounded = np.round(points, ROUND_DECIMALS) + 0.0  # + 0.0: no -0.0
    keep = np.concatenate([[True], np.any(np.diff(rounded, axis=0) != 0, axis=1)])
    return rounded[keep].tolist()


def _style(mark_type: str) -> str | None:
    if mark_type == "none":
        return None
    return "broken" if mark_type in BROKEN_MARKS else "solid"


def _mark_spans(marks: tuple[RoadMark, ...], kind: str, start_m: float, end_m: float) -> list[tuple[float, float, str]]:
    """(from s, to s, style) of the drawn parts of a border over [start_m, end_m]; equal neighbours merged."""
    records = [(start_m, DEFAULT_STYLE[kind])] if not marks or marks[0].s_offset_m > 0 else []
    records += [(start_m + mark.s_offset_m, _style(mark.type)) for mark in marks]
    spans: list[tuple[float, float, str]] = []
    for (lo, style), (hi, _) in zip(records, [*records[1:], (end_m, None)], strict=True):
        lo, hi = max(lo, start_m), min(hi, end_m)
        if style is None or hi <= lo:
            continue
        if spans and spans[-1][2] == style and spans[-1][1] == lo:
            spans[-1] = (spans[-1][0], hi, style)
        else:
            spans.append((lo, hi, style))
    return spans


def _carriageway(lane: Lane) -> bool:
    return lane.type in CARRIAGEWAY_TYPES


def _side_borders(lanes: list[Lane], widths: list[np.ndarray], offset: np.ndarray, sign: float) -> list[_Border]:
    """The outer border of each lane of one side, outward (kind by the lane and the one beyond it)."""
    borders = []
    t = offset
    for index, (lane, width) in enumerate(zip(lanes, widths, strict=True)):
        t = t + sign * width
        beyond = lanes[index + 1] if index + 1 < len(lanes) else None
        inner_lane = beyond is not None and _carriageway(lane) and _carriageway(beyond)
        borders.append(_Border(t, "lane" if inner_lane else "edge", lane.marks, ("lane", lane.line)))
    return borders


def _wide_lanes(lanes: tuple[Lane, ...], stations: np.ndarray, section_s_m: float) -> tuple[list[Lane], list]:
    """The lanes at least `MIN_LANE_WIDTH_M` wide somewhere in the section, and their widths at `stations`."""
    kept, widths = [], []
    for lane in lanes:
        width = cubic_at(lane.widths, stations, section_s_m)
        if np.max(np.abs(width)) >= MIN_LANE_WIDTH_M:
            kept.append(lane)
            widths.append(width)
    return kept, widths


def _stations(start_m: float, end_m: float, breaks: list[float]) -> np.ndarray:
    """Stations every `DENSE_SPACING_M` or less from `start_m` to `end_m`, with every break inside included."""
    count = max(2, math.ceil((end_m - start_m) / DENSE_SPACING_M - 1e-9) + 1)
    inside = [s for s in breaks if start_m < s < end_m]
    return np.unique(np.concatenate([np.linspace(start_m, end_m, count), inside]))


class _RoadSampler:
    """The lines and surfaces of one road."""

    def __init__(self, road: Road, source: str = "OpenDRIVE") -> None:
        self.road, self.source = road, source
        self.lines: list[dict[str, Any]] = []
        self.surfaces: list[dict[str, Any]] = []

    def sample(self) -> None:
        road = self.road
        ends = [section.s_m for section in road.sections[1:]] + [road.length_m]
        for section, end_m in zip(road.sections, ends, strict=True):
            start_m = max(0.0, min(section.s_m, road.length_m))
            end_m = min(end_m, road.length_m)
            if end_m - start_m > 1e-9:
                self.section(section, start_m, end_m)

    def check_reach(self, points: np.ndarray, s_m: np.ndarray, element: tuple[str, int] | None) -> None:
        """Refuse points beyond the `coordinate_m` limit (or not finite), naming the element that puts them there:
        `element` (tag, line), or the geometry of the reference line at that station."""
        bound = limit("coordinate_m")
        far = np.flatnonzero(~(np.abs(points) <= bound).all(axis=1))
        if not far.size:
            return
        index = int(far[0])
        tag, line = element if element is not None else _geometry_at(self.road, float(s_m[index]))
        x, y = points[index]
        what = "" if element is None else "its border "
        raise UserInputError(
            f"{self.source}: line {line}: <{tag}> of road {self.road.id!r}: {what}reaches ({x:.6g}, {y:.6g}) m at "
            f"s = {s_m[index]:g} m, beyond the limit of {amount(bound)} m ({LIMITS['coordinate_m'].bounds}; "
            f"{env_name('coordinate_m')} raises it)"
        )

    def section(self, section: LaneSection, start_m: float, end_m: float) -> None:
        marks = [*section.centre_marks, *(m for lane in (*section.left, *section.right) for m in lane.marks)]
        s = _stations(start_m, end_m, [section.s_m + mark.s_offset_m for mark in marks])
        x_ref, y_ref, heading = reference_poses(self.road, s)
        self.check_reach(np.column_stack([x_ref, y_ref]), s, None)
        offset = lane_offset_m(self.road, s)
        left, left_widths = _wide_lanes(section.left, s, section.s_m)
        right, right_widths = _wide_lanes(section.right, s, section.s_m)
        if not left and not right:
            return
        left_borders = _side_borders(left, left_widths, offset, 1.0)
        right_borders = _side_borders(right, right_widths, offset, -1.0)
        borders = [*left_borders, *right_borders]
        opposite = left and right and _carriageway(left[0]) and _carriageway(right[0])
        borders.append(
            _Border(offset, "centre" if opposite else "edge", section.centre_marks, ("laneSection", section.line))
        )

        def world(t: np.ndarray, part: slice | np.ndarray = slice(None)) -> np.ndarray:
            """Points [N, 2] at lateral offsets `t` of the stations `part`."""
            x, y, h = x_ref[part], y_ref[part], heading[part]
            return np.column_stack([x - t[part] * np.sin(h), y + t[part] * np.cos(h)])

        for border in borders:
            self.check_reach(world(border.t_m), s, border.element)
            for lo, hi, style in _mark_spans(border.marks, border.kind, start_m, end_m):
                part = (s >= lo - 1e-9) & (s <= hi + 1e-9)
                points = _rounded(simplified(world(border.t_m, part)))
                if len(points) >= 2:
                    self.lines.append({"kind": border.kind, "style": style, "points": points})
        outer_left = left_borders[-1].t_m if left else offset
        outer_right = right_borders[-1].t_m if right else offset
        outline = _rounded(np.concatenate([simplified(world(outer_right)), simplified(world(outer_left))[::-1]]))
        if len(outline) >= 3:
            self.surfaces.append({"points": outline})


def sample_count(road: Road) -> int:
    """How many border points drawing `road` evaluates: each lane section's stations (`_stations`) x its borders
    (every lane's outer border and the offset border), counted before anything is sampled."""
    ends = [section.s_m for section in road.sections[1:]] + [road.length_m]
    total = 0
    for section, end_m in zip(road.sections, ends, strict=True):
        start_m, end_m = max(0.0, min(section.s_m, road.length_m)), min(end_m, road.length_m)
        if end_m - start_m > 1e-9:
            marks = len(section.centre_marks) + sum(len(lane.marks) for lane in (*section.left, *section.right))
            stations = max(2, math.ceil((end_m - start_m) / DENSE_SPACING_M - 1e-9) + 1) + marks
            total += stations * (len(section.left) + len(section.right) + 1)
    return total


def sampling_excess(network: Network) -> str | None:
    """Why drawing `network` would sample too many points (limit `road_samples`), naming its largest road; or None."""
    counts = {road_id: sample_count(road) for road_id, road in network.roads.items()}
    reason = excess("road_samples", sum(counts.values()))
    if reason is None:
        return None
    road = network.roads[max(counts, key=counts.__getitem__)]
    lanes = max(len(section.left) + len(section.right) for section in road.sections)
    return (
        f"{network.source or 'OpenDRIVE'}: line {road.line}: <road> id {road.id!r} ({road.length_m:g} m, {lanes} "
        f"lanes), the largest of {len(counts)} road(s): {reason}"
    )


def _geometry_at(road: Road, s_m: float) -> tuple[str, int]:
    """(tag, line) of the plan-view geometry that holds station `s_m`."""
    starts = [geometry.s_m for geometry in road.geometries]
    geometry = road.geometries[max(0, int(np.searchsorted(starts, s_m, side="right")) - 1)]
    return "geometry", geometry.line


def road_drawing(network: Network) -> tuple[list[dict[str, Any]], list[dict[str, Any]]]:
    """(lines, surfaces) of every road of `network`, as `road.lines` / `road.surfaces` mappings."""
    lines: list[dict[str, Any]] = []
    surfaces: list[dict[str, Any]] = []
    for road in network.roads.values():
        sampler = _RoadSampler(road, network.source or "OpenDRIVE")
        sampler.sample()
        lines += sampler.lines
        surfaces += sampler.surfaces
    return lines, surfaces


def drawing_fields(network: Network) -> tuple[dict[str, Any], str | None]:
    """The `road` fields `lines` and `surfaces` of `network`, or none and why (beyond the `road_samples` budget,
    checked before sampling, or the `road_points` budget)."""
    reason = sampling_excess(network)
    if reason is not None:
        return {}, f"the drawn road is not kept: {reason}; figures draw the generated layout"
    lines, surfaces = road_drawing(network)
    count = sum(len(item["points"]) for item in (*lines, *surfaces))
    reason = excess("road_points", count)
    if reason is not None:
        return {}, f"the drawn road is not kept: {reason}; figures draw the generated layout"
    return {"lines": lines, "surfaces": surfaces}, None
