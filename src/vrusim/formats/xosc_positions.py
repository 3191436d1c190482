"""OpenSCENARIO `<Position>` to a world pose: WorldPosition directly, LanePosition / RoadPosition on the road.

Lane and road positions go through the OpenDRIVE reader (`xodr_lanes`): heading of the road's s axis, turned
by an `<Orientation>` (relative: added; absolute: replaces it). Other position kinds (relative, route,
geographic, trajectory positions) are refused. z, pitch and roll are ignored (vrusim is planar).
"""

from __future__ import annotations

from vrusim.formats.xml_file import Element
from vrusim.formats.xodr_lanes import lane_position, road_position
from vrusim.formats.xodr_model import Network
from vrusim.formats.xosc_document import XoscDocument
from vrusim.formats.xosc_model import WorldPose

POSITION_KINDS = {"WorldPosition", "LanePosition", "RoadPosition"}


def _oriented(doc: XoscDocument, element: Element, heading_rad: float) -> float:
    orientation = doc.optional(element, "Orientation")
    if orientation is None:
        return heading_rad
    turn = doc.number(orientation, "h", 0.0)
    if doc.choice(orientation, "type", ("relative", "absolute"), "relative") == "absolute":
        return turn
    return heading_rad + turn


def read_position(doc: XoscDocument, position: Element, network: Network) -> WorldPose:
    """The world pose of a `<Position>` element (m, m, rad)."""
    kind = doc.single(position, POSITION_KINDS)
    if kind.tag == "WorldPosition":
        doc.children(kind, set())
        return WorldPose(doc.number(kind, "x"), doc.number(kind, "y"), doc.number(kind, "h", 0.0))
    doc.children(kind, {"Orientation"})
    road_id, s_m = doc.text(kind, "roadId"), doc.number(kind, "s")
    if kind.tag == "LanePosition":
        lane_text = doc.text(kind, "laneId")
        try:
            lane_id = int(lane_text)
        except ValueError:
            raise doc.fail(kind, f"attribute laneId: expected a whole number, got {lane_text!r}") from None
        x, y, heading = lane_position(network, road_id, lane_id, s_m, doc.number(kind, "offset", 0.0))
    else:
        x, y, heading = road_position(network, road_id, s_m, doc.number(kind, "t"))
    return WorldPose(float(x), float(y), _oriented(doc, kind, float(heading)))
