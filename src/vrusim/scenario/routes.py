"""Scenario routes and VRU paths as geometric path specifications (`vrusim.geometry.paths`)."""

from __future__ import annotations

import math

from vrusim.geometry.paths import SAMPLE_SPACING_M, Arc, Clothoid, Line, PathSpec, Piece, PolylineSpec
from vrusim.scenario.schema import Ego, Route, Vru


def turn_pieces(route: Route) -> tuple[Piece, ...]:
    """The turning part of a left / right route: an arc, or clothoid + arc + clothoid when `clothoid_angle_deg` > 0."""
    sign = 1.0 if route.kind == "left" else -1.0
    arc = Arc(route.radius_m, sign * math.radians(route.angle_deg))
    if route.clothoid_angle_deg == 0.0:
        return (arc,)
    entry, arc_curvature = sign / route.clothoid_entry_radius_m, sign / route.radius_m
    length = 2 * math.radians(route.clothoid_angle_deg) / (1 / route.clothoid_entry_radius_m + 1 / route.radius_m)
    return Clothoid(entry, arc_curvature, length), arc, Clothoid(arc_curvature, entry, length)


def trimmed(pieces: tuple[Piece, ...], skip_m: float) -> tuple[Piece, ...]:
    """`pieces` without their first `skip_m` metres (a clothoid cut part-way starts at its curvature there)."""
    out: list[Piece] = []
    for piece in pieces:
        if skip_m >= piece.length_m:
            skip_m -= piece.length_m
            continue
        if skip_m > 0:
            kept = 1.0 - skip_m / piece.length_m
            if isinstance(piece, Clothoid):
                start = piece.start_curvature_per_m + piece.sharpness_per_m2 * skip_m
                piece = Clothoid(start, piece.end_curvature_per_m, piece.length_m - skip_m)
            elif isinstance(piece, Arc):
                piece = Arc(piece.radius_m, piece.angle_rad * kept)
            else:
                piece = Line(piece.length_m - skip_m)
            skip_m = 0.0
        out.append(piece)
    return tuple(out)


def route_spec(route: Route, x0_m: float, y0_m: float, heading0_rad: float) -> PathSpec:
    """A route as a path from the start pose of the rear axle (m, m, rad)."""
    if route.kind == "straight":
        return PathSpec(x0_m, y0_m, heading0_rad, (Line(route.length_m),))
    turn = trimmed(turn_pieces(route), route.start_in_turn_m)
    exit_length = route.length_m - route.turn_at_m - sum(piece.length_m for piece in turn)
    pieces = tuple(p for p in (Line(route.turn_at_m), *turn, Line(exit_length)) if p.length_m > 0)
    return PathSpec(x0_m, y0_m, heading0_rad, pieces)


def ego_route_spec(ego: Ego) -> PathSpec:
    """The route of the ego's rear-axle centre, which starts behind the rectangle centre given in `ego.start`.

    A reversing ego is packed as a vehicle mirrored front to back (see `Ego.travel_heading_deg`): its
    simulated rear axle is the real front axle.
    """
    heading = math.radians(ego.travel_heading_deg)
    back = ego.length_m / 2 - ego.trailing_overhang_m
    x0 = ego.start.x_m - back * math.cos(heading)
    y0 = ego.start.y_m - back * math.sin(heading)
    return route_spec(ego.route, x0, y0, heading)


def vru_path_spec(vru: Vru) -> PathSpec | PolylineSpec:
    """A VRU's path: a straight line along `heading_deg`, or the polyline through its waypoints."""
    if vru.heading_deg is not None:
        return PathSpec(vru.start.x_m, vru.start.y_m, math.radians(vru.heading_deg), (Line(SAMPLE_SPACING_M),))
    points = [(vru.start.x_m, vru.start.y_m)] + [(p.x_m, p.y_m) for p in vru.path or []]
    return PolylineSpec(tuple(points))
