"""The OpenDRIVE road of a scenario: a straight two-lane road or a four-arm junction, in vrusim's world frame.

Coordinates: OpenDRIVE's inertial frame IS vrusim's world frame (x, y in m, heading in rad counter-clockwise
from +x, z = 0 on a flat road); no offset, rotation or scaling. The road is centred on the origin like
`viz.scene` draws it: the straight road's reference line runs along y = 0 from x = -half to x = +half, one
lane of `lane_width_m` on each side (right-hand traffic: the lane y < 0 carries +x traffic). The junction
has four such arms (west, east along y = 0; south, north along x = 0) from |coordinate| = lane_width_m to
half, joined by a junction (square of side 2 lane_width_m) whose connecting roads scenariogeneration
generates. Every arm's reference line points in +x or +y, so its right lane (negative id) carries traffic
in that direction.
"""

from __future__ import annotations

import math

from vrusim.extras import extra

with extra("export"):
    from scenariogeneration import xodr

from vrusim.scenario.schema import Road

JUNCTION_ID = 100
"""OpenDRIVE id of the junction (arms are roads 1-4, connecting roads 100 and up)."""


def _arm(road_id: int, length_m: float, lane_width_m: float) -> xodr.Road:
    """A straight two-lane road: solid edge lines, a broken centre line, flat."""
    road = xodr.create_road(
        xodr.Line(length_m),
        road_id,
        left_lanes=1,
        right_lanes=1,
        lane_width=lane_width_m,
        center_road_mark=xodr.std_roadmark_broken(),
    )
    road.add_elevation(0.0, 0.0, 0.0, 0.0, 0.0)
    road.add_superelevation(0.0, 0.0, 0.0, 0.0, 0.0)
    return road


def road_network(road: Road, half_length_m: float, name: str) -> xodr.OpenDrive:
    """The OpenDRIVE (1.5, scenariogeneration's default) network of `road`; arms reach |x|, |y| = `half_length_m`."""
    w = road.lane_width_m
    odr = xodr.OpenDrive(name)
    if road.layout == "straight":
        straight = _arm(1, 2 * half_length_m, w)
        straight.planview.set_start_point(-half_length_m, 0.0, 0.0)
        odr.add_road(straight)
        odr.adjust_roads_and_lanes()
        return odr
    if half_length_m <= w:
        raise ValueError(f"half_length_m ({half_length_m} m) must exceed the lane width ({w} m)")
    arm_m = half_length_m - w
    junction = xodr.CommonJunctionCreator(JUNCTION_ID, "junction", startnum=JUNCTION_ID)
    # id: (start x, start y, heading of the reference line, end touching the junction)
    arms = {
        1: (-half_length_m, 0.0, 0.0, "successor"),
        2: (w, 0.0, 0.0, "predecessor"),
        3: (0.0, -half_length_m, math.pi / 2, "successor"),
        4: (0.0, w, math.pi / 2, "predecessor"),
    }
    for road_id, (x, y, heading, link) in arms.items():
        arm = _arm(road_id, arm_m, w)
        if road_id == 1:  # anchors the network; the others are placed through the junction
            arm.planview.set_start_point(x, y, heading)
        if link == "successor":  # the creator wants the junction end and the heading pointing into the junction
            at_x, at_y, into = x + arm_m * math.cos(heading), y + arm_m * math.sin(heading), heading
        else:
            at_x, at_y, into = x, y, heading + math.pi
        junction.add_incoming_road_cartesian_geometry(arm, at_x, at_y, into, link)
        odr.add_road(arm)
    for first in arms:
        for second in arms:
            if first < second:
                junction.add_connection(first, second)
    junction.add_constant_elevation(0.0)
    odr.add_junction_creator(junction)
    odr.adjust_roads_and_lanes()
    return odr
