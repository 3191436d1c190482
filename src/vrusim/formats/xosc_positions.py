"""OpenSCENARIO `<Position>` to a world pose: WorldPosition directly, LanePosition / RoadPosition on the road.

Lane and road positions go through the OpenDRIVE reader (`xodr_lanes`): heading of the road's s axis, turned
by an `<Orientation>` (relative: added; absolute: replaces it). Positions relative to an entity placed earlier in
`<Init>` go through `xosc_relative_positions` where the caller passes the placed entities. Other position kinds
(route, geographic, trajectory positions) are refused. z, pitch and roll are ignored (vrusim is planar).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping

import numpy as np

from vrusim.errors import UserInputError
from vrusim.formats.xml_file import Element
from vrusim.formats.xodr_geometry import Poses
from vrusim.formats.xodr_lanes import lane_position, road_position
from vrusim.formats.xodr_model import Network
from vrusim.formats.xosc_document import XoscDocument
from vrusim.formats.xosc_model import WorldPose
from vrusim.formats.xosc_relative_positions import RELATIVE_KINDS, oriented, relative_position

POSITION_KINDS = {"WorldPosition", "LanePosition", "RoadPosition"}


def read_position(
    doc: XoscDocument, position: Element, network: Network, placed: Mapping[str, WorldPose] | None = None
) -> WorldPose:
    """The world pose of a `<Position>` element (m, m, rad); relative positions need `placed` (entity name ->
    its pose in `<Init>`, entities placed so far), else they are refused."""
    kind = doc.single(position, POSITION_KINDS | (RELATIVE_KINDS if placed is not None else set()))
    if kind.tag in RELATIVE_KINDS:
        return relative_position(doc, kind, network, placed)
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
        offset = doc.number(kind, "offset", 0.0)
        poses = _on_road(doc, kind, lambda: lane_position(network, road_id, lane_id, s_m, offset))
    else:
        t_m = doc.number(kind, "t")
        poses = _on_road(doc, kind, lambda: road_position(network, road_id, s_m, t_m))
    x, y, heading = (float(np.ravel(value)[0]) for value in poses)
    return WorldPose(x, y, oriented(doc, kind, heading))


def _on_road(doc: XoscDocument, kind: Element, where: Callable[[], Poses]) -> Poses:
    """`where()`, its road error (unknown road, station or lane) naming the element and its line."""
    try:
        return where()
    except UserInputError as error:
        raise doc.fail(kind, str(error)) from None
