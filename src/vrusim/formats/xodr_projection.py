"""World -> road coordinates on an OpenDRIVE network: the nearest point of a road's reference line, and the lane a
lateral offset lies in.

A world point (x, y) is projected onto each road's reference line: the station s whose reference point is nearest
(a 0.5 m sample grid, a golden-section search between the neighbours of the nearest sample, then Newton steps
to round-off);
t is the signed distance to the left of the s axis. Of all roads, the nearest one on which the point lies inside a
lane wins; within 1 um, a road outside a junction is preferred, then the first in the file. Lengths in m, angles in
rad.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from vrusim.errors import UserInputError
from vrusim.formats.xodr_geometry import reference_poses
from vrusim.formats.xodr_lanes import lane_borders_t, lane_offset_m
from vrusim.formats.xodr_model import Network, Road
from vrusim.limits import check_limit

GRID_M = 0.5
"""Spacing of the first, coarse search along a reference line, m."""
GOLDEN_STEPS = 80
"""Golden-section steps of the fine search (the bracket shrinks by 0.618 each step: to round-off)."""
NEWTON_STEPS = 3
"""Newton steps after the golden section."""
CURVATURE_STEP_M = 1e-4
"""Station step of the finite difference giving the reference line's curvature, m."""
TIE_M = 1e-6
"""Two roads this close to the point are a tie."""


@dataclass(frozen=True)
class RoadCoordinates:
    """A point in road coordinates: station `s_m` along road `road_id`, `t_m` to the left of its reference line,
    the lane it lies in (None: off every lane), the heading of the s axis there (rad) and the distance from the
    point to (s, t) (0 when the point projects inside the road)."""

    road_id: str
    s_m: float
    t_m: float
    lane_id: int | None
    heading_rad: float
    distance_m: float


def _distance_sq(road: Road, x_m: float, y_m: float, s_m: np.ndarray) -> np.ndarray:
    rx, ry, _ = reference_poses(road, s_m)
    return (rx - x_m) ** 2 + (ry - y_m) ** 2


def nearest_station_m(road: Road, x_m: float, y_m: float) -> float:
    """The station of the reference point of `road` nearest to (x_m, y_m), m."""
    count = max(2, math.ceil(road.length_m / GRID_M) + 1)
    grid = np.linspace(0.0, road.length_m, count)
    best = int(np.argmin(_distance_sq(road, x_m, y_m, grid)))
    lo, hi = grid[max(best - 1, 0)], grid[min(best + 1, count - 1)]
    ratio = (math.sqrt(5.0) - 1.0) / 2.0
    a, b = hi - ratio * (hi - lo), lo + ratio * (hi - lo)
    fa, fb = _distance_sq(road, x_m, y_m, np.array([a, b]))
    for _ in range(GOLDEN_STEPS):
        if fa < fb:
            hi, b, fb = b, a, fa
            a = hi - ratio * (hi - lo)
            fa = float(_distance_sq(road, x_m, y_m, np.array([a]))[0])
        else:
            lo, a, fa = a, b, fb
            b = lo + ratio * (hi - lo)
            fb = float(_distance_sq(road, x_m, y_m, np.array([b]))[0])
    return _newton(road, x_m, y_m, float(np.clip((lo + hi) / 2, 0.0, road.length_m)))


def _newton(road: Road, x_m: float, y_m: float, s_m: float) -> float:
    """`s_m` refined by Newton steps on (p - r(s)) . T(s) = 0 (T: the unit tangent, its derivative from the
    heading's curvature), which the golden section only finds to about 1e-8 m; kept inside the road."""
    for _ in range(NEWTON_STEPS):
        near = np.clip(np.array([s_m - CURVATURE_STEP_M, s_m, s_m + CURVATURE_STEP_M]), 0.0, road.length_m)
        rx, ry, heading = reference_poses(road, near)
        curvature = (heading[2] - heading[0]) / (near[2] - near[0])
        dx, dy = x_m - rx[1], y_m - ry[1]
        along = dx * math.cos(heading[1]) + dy * math.sin(heading[1])
        left = -dx * math.sin(heading[1]) + dy * math.cos(heading[1])
        slope = 1.0 - curvature * left
        if slope <= 0.0:  # at or beyond the centre of curvature: keep the grid's answer
            return s_m
        s_m = float(np.clip(s_m + along / slope, 0.0, road.length_m))
    return s_m


def lane_at(road: Road, s_m: float, t_m: float) -> int | None:
    """The lane at road position (s, t): left lanes when t lies left of the centre lane, else right; None when t
    is outside every lane (or on the centre lane of a road without lanes on that side)."""
    side = 1 if t_m > float(lane_offset_m(road, np.array([s_m]))[0]) else -1
    section = [sec for sec in road.sections if sec.s_m <= s_m + 1e-9] or [road.sections[0]]
    lanes = section[-1].left if side > 0 else section[-1].right
    for lane in lanes:
        inner, outer = lane_borders_t(road, lane.id, s_m)
        low, high = sorted((float(inner[0]), float(outer[0])))
        if low - 1e-9 <= t_m <= high + 1e-9:
            return lane.id
    return None


def road_coordinates(road: Road, x_m: float, y_m: float) -> RoadCoordinates:
    """(x, y) in the coordinates of `road`."""
    s = nearest_station_m(road, x_m, y_m)
    rx, ry, heading = (float(v[0]) for v in reference_poses(road, s))
    dx, dy = x_m - rx, y_m - ry
    t = -dx * math.sin(heading) + dy * math.cos(heading)
    along = dx * math.cos(heading) + dy * math.sin(heading)
    return RoadCoordinates(road.id, s, t, lane_at(road, s, t), heading, abs(along))


def check_projection_work(network: Network) -> None:
    """Refuse, before sampling, a network whose reference lines a projection would sample at more than
    `road_samples` points (every `GRID_M` along every road: 2,000 roads of 100 km took 70 s per position)."""
    count = sum(max(2, math.ceil(road.length_m / GRID_M) + 1) for road in network.roads.values())
    check_limit(
        "road_samples",
        count,
        f"{network.source or 'OpenDRIVE'}: projecting a position onto its {len(network.roads):,} roads (reference "
        f"lines every {GRID_M:g} m)",
    )


def project(network: Network, x_m: float, y_m: float) -> RoadCoordinates:
    """(x, y) on the road it lies on (see the module docstring); a UserInputError when it lies on no lane."""
    check_projection_work(network)
    found = [road_coordinates(road, x_m, y_m) for road in network.roads.values()]
    on_lane = [c for c in found if c.lane_id is not None and c.distance_m < 1e-3]
    if not on_lane:
        raise UserInputError(
            f"{network.source or 'OpenDRIVE'}: the point ({x_m:g}, {y_m:g}) lies on no lane of any road"
        )
    nearest = min(abs(c.t_m) for c in on_lane)
    ties = [c for c in on_lane if abs(c.t_m) <= nearest + TIE_M]
    return next((c for c in ties if network.roads[c.road_id].junction == "-1"), ties[0])
