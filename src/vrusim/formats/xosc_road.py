"""vrusim's `Road` fields from an OpenDRIVE network: layout, lane width and drawn length.

layout: "intersection" when the network has a junction, else "straight". lane_width_m: the width (at its
start) of the first right lane (id -1) of the first road. length_m: twice the farthest reach of any road end
from the origin along x or y (the export centres the road on the origin). `drawn_road_fields` adds the network's
real lines and paved surfaces (`xodr_drawing`), which figures draw instead of the layout. The road only draws the
scene in vrusim; it does not change a run.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from vrusim.errors import UserInputError
from vrusim.formats.xodr_drawing import drawing_fields
from vrusim.formats.xodr_geometry import reference_poses
from vrusim.formats.xodr_model import Network
from vrusim.limits import excess


def road_fields(network: Network) -> dict[str, Any]:
    """The `Road` fields of `network` (m)."""
    roads = list(network.roads.values())
    if not roads:
        raise UserInputError(f"{network.source or 'OpenDRIVE'}: has no <road>")
    first = roads[0]
    lanes = [lane for section in first.sections for lane in section.right if lane.id == -1]
    if not lanes or not lanes[0].widths:
        raise UserInputError(f"{network.source or 'OpenDRIVE'}: road {first.id!r} has no right lane -1 with a width")
    reach = 0.0
    for road in roads:
        x, y, _ = reference_poses(road, np.array([0.0, road.length_m]))
        reach = max(reach, float(np.max(np.abs(x))), float(np.max(np.abs(y))))
        reason = excess("length_m", 2 * reach)
        if reason is not None:
            raise UserInputError(
                f"{network.source or 'OpenDRIVE'}: line {road.line}: <road> id {road.id!r} ends "
                f"{reach:.6g} m from the origin; the road's length (road.length_m, twice that): {reason}"
            )
    return {
        "layout": "intersection" if network.junctions else "straight",
        "lane_width_m": lanes[0].widths[0].a,
        "length_m": 2 * reach,
    }


def drawn_road_fields(network: Network, warnings: list[str] | None = None) -> dict[str, Any]:
    """`road_fields` with the drawn `lines` and `surfaces`; beyond the `road_points` budget without them, and the
    reason appended to `warnings`."""
    fields, reason = drawing_fields(network)
    if reason is not None and warnings is not None:
        warnings.append(reason)
    return road_fields(network) | fields
