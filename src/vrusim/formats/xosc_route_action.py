"""`RoutingAction/AssignRouteAction`: a `<Route>` of `<Waypoint>`s (inline or a RouteCatalog entry) as the
vertices of the lane centre lines it drives (ASAM OpenSCENARIO XML 1.3, "Routes").

Each waypoint's `<Position>` is put on a lane: a LanePosition names its lane, a RoadPosition's (s, t) and any
other position's world point are put on the lane they lie in (`xodr_projection`). Between consecutive waypoints
the route drives lane after lane (`xodr_lane_graph`: road links and junction connections, no lane changes)
along the least-cost lane sequence of the later waypoint's `routeStrategy`: `shortest` and `fastest` by length
(vrusim reads no speed limits, so the fastest route is the shortest at one speed everywhere), `leastIntersections`
by the number of junction roads, then length; `random` is refused (not reproducible). Two waypoints on one lane
with the second ahead are joined along it. The centre lines are sampled every `SPACING_M` at most (exact points
on the lane centre; headings of its tangent) from the first waypoint's station to the last one's; a straight
run-out of `OVERRUN_M` follows (as for a clothoid: `xosc_clothoid.with_run_out`). A closed route is refused.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from vrusim.errors import UserInputError
from vrusim.formats.xml_file import Element, shown
from vrusim.formats.xodr_lane_graph import Cost, junction_cost, length_cost, shortest_lanes
from vrusim.formats.xodr_lanes import lane_centre_t, lane_position, road_to_world
from vrusim.formats.xodr_model import Network
from vrusim.formats.xodr_projection import lane_at, project
from vrusim.formats.xodr_route import MAX_GAP_M, along_s
from vrusim.formats.xosc_catalogs import catalog_entry
from vrusim.formats.xosc_clothoid import with_run_out
from vrusim.formats.xosc_document import XoscDocument
from vrusim.formats.xosc_model import SampledShape, WorldPose
from vrusim.formats.xosc_positions import read_position
from vrusim.geometry.paths import SAMPLE_SPACING_M
from vrusim.limits import check_limit

SPACING_M = SAMPLE_SPACING_M
"""Largest distance along s between two route vertices, m."""
TANGENT_STEP_M = 1e-4
"""Station step of the 3-point finite difference giving a lane centre's heading (second order), m."""
DISTINCT_M = 1e-6
"""A vertex closer than this to the previous one is dropped (vrusim paths need distinct points), m."""
STRATEGIES: dict[str, Cost] = {"shortest": length_cost, "fastest": length_cost, "leastIntersections": junction_cost}


@dataclass(frozen=True)
class _Stop:
    """A waypoint on a lane: road, lane, station (m), and its element."""

    road_id: str
    lane_id: int
    s_m: float
    element: Element


def _on_lane(doc: XoscDocument, waypoint: Element, network: Network, placed: Mapping[str, WorldPose] | None) -> _Stop:
    position = doc.child(waypoint, "Position")
    kind = position.children[0] if len(position.children) == 1 else None
    try:
        if kind is not None and kind.tag == "LanePosition":
            read_position(doc, position, network, placed)  # checks the element and the lane
            return _Stop(doc.text(kind, "roadId"), int(doc.text(kind, "laneId")), doc.number(kind, "s"), waypoint)
        if kind is not None and kind.tag == "RoadPosition":
            read_position(doc, position, network, placed)
            road_id, s, t = doc.text(kind, "roadId"), doc.number(kind, "s"), doc.number(kind, "t")
            lane = lane_at(network.roads[road_id], s, t)
            if lane is None:
                raise UserInputError(f"road {shown(road_id)}: t = {t:g} m at s = {s:g} m lies on no lane")
            return _Stop(road_id, lane, s, waypoint)
        pose = read_position(doc, position, network, placed)
        where = project(network, pose.x_m, pose.y_m)
        assert where.lane_id is not None
        return _Stop(where.road_id, where.lane_id, where.s_m, waypoint)
    except UserInputError as error:
        if str(error).startswith(doc.source):
            raise
        raise doc.fail(waypoint, f"cannot be put on a lane: {error}") from None


def _ahead(network: Network, a: _Stop, b: _Stop) -> bool:
    """Whether `b` lies on `a`'s lane at or ahead of `a` in its direction of travel."""
    if (a.road_id, a.lane_id) != (b.road_id, b.lane_id):
        return False
    forward = along_s(network.roads[a.road_id], a.lane_id)
    return b.s_m >= a.s_m if forward else b.s_m <= a.s_m


def _lane_poses(network: Network, road_id: str, lane_id: int, s_from: float, s_to: float) -> list[WorldPose]:
    """Poses on the lane centre from s_from to s_to (either order), at most SPACING_M apart; heading of travel."""
    road = network.roads[road_id]
    count = max(2, math.ceil(abs(s_to - s_from) / SPACING_M - 1e-9) + 1)
    s = np.linspace(s_from, s_to, count)
    x, y, _ = lane_position(network, road_id, lane_id, s)
    direction = 1.0 if s_to >= s_from else -1.0
    step = min(TANGENT_STEP_M, road.length_m / 2)
    centre = np.clip(s, step, road.length_m - step)  # a 3-point stencil kept on the road
    u = (s - centre) / step
    (xa, ya), (xb, yb), (xc, yc) = (
        road_to_world(road, centre + k * step, lane_centre_t(road, lane_id, centre + k * step))[:2] for k in (-1, 0, 1)
    )
    # derivative of the quadratic through the stencil at u (second order also at a road end)
    dx = (xc - xa) / 2 + u * (xa - 2 * xb + xc)
    dy = (yc - ya) / 2 + u * (ya - 2 * yb + yc)
    heading = np.arctan2(direction * dy, direction * dx)
    return [WorldPose(float(a), float(b), float(h)) for a, b, h in zip(x, y, heading, strict=True)]


def _legs(network: Network, stops: list[_Stop], strategies: list[str]) -> list[tuple[str, int, float, float]]:
    """(road, lane, s from, s to) of each lane driven, in order."""
    legs: list[tuple[str, int, float, float]] = []
    for a, b, strategy in zip(stops, stops[1:], strategies[1:], strict=False):
        if _ahead(network, a, b):
            legs.append((a.road_id, a.lane_id, a.s_m, b.s_m))
            continue
        lanes = shortest_lanes(network, (a.road_id, a.lane_id), (b.road_id, b.lane_id), STRATEGIES[strategy])
        for index, (road_id, lane_id) in enumerate(lanes):
            road = network.roads[road_id]
            forward = along_s(road, lane_id)
            entry, exit_ = (0.0, road.length_m) if forward else (road.length_m, 0.0)
            legs.append((road_id, lane_id, a.s_m if index == 0 else entry, b.s_m if index == len(lanes) - 1 else exit_))
    return legs


def route_shape(
    doc: XoscDocument, route: Element, network: Network, placed: Mapping[str, WorldPose] | None
) -> SampledShape:
    """The vertices of a `<Route>` element read in `doc`."""
    doc.children(route, {"ParameterDeclarations", "Waypoint"})
    declarations = route.first("ParameterDeclarations")
    if declarations is not None and declarations.children:
        raise doc.fail(declarations, "is not supported in an inline route (declare parameters at the top of the file)")
    if doc.choice(route, "closed", ("false", "true", "0", "1"), "false") in ("true", "1"):
        raise doc.fail(route, "a closed route is not supported")
    waypoints = route.all("Waypoint")
    if len(waypoints) < 2:
        raise doc.fail(route, "needs at least two <Waypoint>")
    strategies = []
    for waypoint in waypoints:
        doc.children(waypoint, {"Position"})
        strategy = doc.choice(waypoint, "routeStrategy", ("fastest", "shortest", "leastIntersections", "random"))
        if strategy == "random":
            raise doc.fail(waypoint, "routeStrategy random is not supported: the route would not be reproducible")
        strategies.append(strategy)
    stops = [_on_lane(doc, waypoint, network, placed) for waypoint in waypoints]
    try:
        legs = _legs(network, stops, strategies)
    except UserInputError as error:
        raise doc.fail(route, f"{error}") from None
    check_limit(
        "length_m", sum(abs(leg[3] - leg[2]) for leg in legs), f"{doc.source}: line {route.line}: <Route> length"
    )
    shape = SampledShape()
    for road_id, lane_id, s_from, s_to in legs:
        poses = _lane_poses(network, road_id, lane_id, s_from, s_to)
        if shape.vertices:
            end = shape.vertices[-1]
            gap = math.dist((end.x_m, end.y_m), (poses[0].x_m, poses[0].y_m))
            if gap > MAX_GAP_M:
                raise doc.fail(route, f"road {shown(road_id)} lane {lane_id} starts {gap:.3g} m from the previous lane")
            poses = poses[1:]
        for pose in poses:
            if math.dist((pose.x_m, pose.y_m), _xy(shape.vertices)) > DISTINCT_M:
                shape.vertices.append(pose)
    if len(shape.vertices) < 2:
        raise doc.fail(route, "has no length: its waypoints are at one point")
    shape.times_s = [None] * len(shape.vertices)
    shape.sources = [(route.tag, route.line)] * len(shape.vertices)
    return with_run_out(shape)


def _xy(vertices: list[WorldPose]) -> tuple[float, float]:
    return (vertices[-1].x_m, vertices[-1].y_m) if vertices else (math.inf, math.inf)


def assign_route(
    doc: XoscDocument, action: Element, network: Network, placed: Mapping[str, WorldPose] | None
) -> SampledShape:
    """The vertices of an `<AssignRouteAction>`: its `<Route>` or a `<CatalogReference>` to a RouteCatalog entry."""
    doc.children(action, {"Route", "CatalogReference"})
    if len(action.children) != 1:
        raise doc.fail(
            action, "needs one <Route> or one <CatalogReference> to a route (followed as a FollowTrajectoryAction is)"
        )
    holder = action.children[0]
    if holder.tag == "CatalogReference":
        entry = catalog_entry(doc, holder, ("RouteCatalog",), {"Route"})
        return route_shape(entry.doc, entry.element, network, placed)
    return route_shape(doc, holder, network, placed)
