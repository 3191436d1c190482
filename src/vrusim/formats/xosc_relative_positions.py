"""OpenSCENARIO positions relative to an entity placed earlier in `<Init>` (ASAM OpenSCENARIO XML 1.3, 6.5
"Positions"): RelativeObjectPosition, RelativeWorldPosition, RelativeRoadPosition and RelativeLanePosition.

The reference is the entity's reference point as its TeleportAction placed it (`placed`: entities in the order of
`<Init>`; a position relative to one placed later, or outside `<Init>` and trajectories, is refused).

- RelativeObjectPosition dx, dy: in the entity's frame (dx along its heading, dy to its left);
- RelativeWorldPosition dx, dy: along the world axes;
- RelativeRoadPosition ds, dt: the entity's road coordinates (`xodr_projection`) moved by ds along s and dt to
  the left;
- RelativeLanePosition dLane, ds (along the reference line) or dsLane (along the centre line of the entity's
  lane), offset: the centre of the lane dLane lanes to the left of the entity's (lane 0 skipped), offset to the
  left of it.

Heading: an `<Orientation type="absolute">` replaces it; `relative` (the default when h is given) adds h to the
reference heading: the entity's for object and world positions, the road's s axis at the target for road and lane
positions. Without `<Orientation>` the heading is that reference heading. z, pitch, roll are ignored.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np

from vrusim.errors import UserInputError
from vrusim.formats.xml_file import Element, shown
from vrusim.formats.xodr_lanes import lane_centre_t, lane_position, road_position
from vrusim.formats.xodr_model import Network
from vrusim.formats.xodr_projection import RoadCoordinates, project
from vrusim.formats.xosc_document import XoscDocument
from vrusim.formats.xosc_model import WorldPose

RELATIVE_KINDS = {"RelativeObjectPosition", "RelativeWorldPosition", "RelativeRoadPosition", "RelativeLanePosition"}
DS_LANE_STEP_M = 0.01
"""Station step over which a lane's centre line is measured for dsLane, m."""


def oriented(doc: XoscDocument, element: Element, reference_rad: float) -> float:
    """The heading of a position with an optional `<Orientation h type>` (rad): `reference_rad` without one,
    turned by h (`relative`, the default) or replaced by it (`absolute`)."""
    orientation = doc.optional(element, "Orientation")
    if orientation is None:
        return reference_rad
    turn = doc.number(orientation, "h", 0.0)
    if doc.choice(orientation, "type", ("relative", "absolute"), "relative") == "absolute":
        return turn
    return reference_rad + turn


def relative_lane_id(lane_id: int, d_lane: int) -> int:
    """The lane `d_lane` lanes to the left of `lane_id` (positive: towards higher ids), skipping centre lane 0."""
    target = lane_id + d_lane
    if lane_id < 0 < target or (lane_id < 0 and target == 0):
        return target + 1
    if lane_id > 0 > target or (lane_id > 0 and target == 0):
        return target - 1
    return target


def _along_lane_s(network: Network, where: RoadCoordinates, lane_id: int, ds_lane_m: float) -> float:
    """The station reached by going `ds_lane_m` along the centre line of lane `lane_id` from `where`."""
    road = network.roads[where.road_id]
    end = road.length_m if ds_lane_m >= 0 else 0.0
    count = max(2, math.ceil(abs(end - where.s_m) / DS_LANE_STEP_M) + 1)
    stations = np.linspace(where.s_m, end, count)
    x, y, _ = lane_position(network, road.id, lane_id, stations)
    walked = np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(x), np.diff(y)))])
    if abs(ds_lane_m) > walked[-1] + 1e-9:
        raise UserInputError(f"road {road.id!r}: dsLane {ds_lane_m:g} m leads past the end of lane {lane_id}")
    return float(np.interp(abs(ds_lane_m), walked, stations))


def _entity(doc: XoscDocument, kind: Element, placed: Mapping[str, WorldPose] | None) -> WorldPose:
    name = doc.text(kind, "entityRef")
    if placed is None:
        raise doc.fail(kind, "is not supported here (relative positions are read in <Init> and trajectories)")
    if name not in placed:
        raise doc.fail(kind, f"entityRef {shown(name)}: no entity of that name is placed earlier in <Init>")
    return placed[name]


def relative_position(
    doc: XoscDocument, kind: Element, network: Network, placed: Mapping[str, WorldPose] | None
) -> WorldPose:
    """The world pose of a relative position element `kind` (one of `RELATIVE_KINDS`)."""
    doc.children(kind, {"Orientation"})
    ref = _entity(doc, kind, placed)
    try:
        if kind.tag == "RelativeObjectPosition":
            dx, dy = doc.number(kind, "dx"), doc.number(kind, "dy")
            cos_h, sin_h = math.cos(ref.heading_rad), math.sin(ref.heading_rad)
            x, y = ref.x_m + dx * cos_h - dy * sin_h, ref.y_m + dx * sin_h + dy * cos_h
            return WorldPose(x, y, oriented(doc, kind, ref.heading_rad))
        if kind.tag == "RelativeWorldPosition":
            x, y = ref.x_m + doc.number(kind, "dx"), ref.y_m + doc.number(kind, "dy")
            return WorldPose(x, y, oriented(doc, kind, ref.heading_rad))
        where = project(network, ref.x_m, ref.y_m)
        if kind.tag == "RelativeRoadPosition":
            s, t = where.s_m + doc.number(kind, "ds"), where.t_m + doc.number(kind, "dt")
            x, y, heading = road_position(network, where.road_id, s, t)
            return WorldPose(float(x[0]), float(y[0]), oriented(doc, kind, float(heading[0])))
        return _relative_lane(doc, kind, network, where)
    except UserInputError as error:
        if str(error).startswith(doc.source):
            raise
        raise doc.fail(kind, f"(relative to {shown(doc.text(kind, 'entityRef'))}): {error}") from None


def _relative_lane(doc: XoscDocument, kind: Element, network: Network, where: RoadCoordinates) -> WorldPose:
    d_lane = doc.number(kind, "dLane")
    if not d_lane.is_integer():
        raise doc.fail(kind, f"attribute dLane: expected a whole number, got {d_lane:g}")
    given = [name for name in ("ds", "dsLane") if name in kind.attrib]
    if len(given) != 1:
        raise doc.fail(kind, "needs exactly one of the attributes ds and dsLane")
    assert where.lane_id is not None  # project() only returns points on a lane
    road = network.roads[where.road_id]
    target = relative_lane_id(where.lane_id, int(d_lane))
    if given[0] == "ds":
        s = where.s_m + doc.number(kind, "ds")
    else:
        s = _along_lane_s(network, where, where.lane_id, doc.number(kind, "dsLane"))
    t = float(lane_centre_t(road, target, s)[0]) + doc.number(kind, "offset", 0.0)
    x, y, heading = road_position(network, road.id, s, t)
    return WorldPose(float(x[0]), float(y[0]), oriented(doc, kind, float(heading[0])))
