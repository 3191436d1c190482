"""Sample OpenDRIVE reference lines and lane centre lines into vrusim polylines, and chain lanes into a route.

A route is a list of (road id, lane id) steps, each lane driven in its direction of travel: right lanes
(id < 0) along +s and left lanes against it under right-hand traffic (`rule="RHT"`, the default), the other
way round under `LHT`. Consecutive lanes must meet (within `MAX_GAP_M`), as they do through a junction's
connecting road. Points are at most `spacing_m` apart along s (exact on the curve; chords between them).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from vrusim.errors import UserInputError
from vrusim.formats.xodr_geometry import reference_poses
from vrusim.formats.xodr_lanes import lane_position
from vrusim.formats.xodr_model import Network, Road
from vrusim.geometry.paths import SAMPLE_SPACING_M, PolylineSpec

MAX_GAP_M = 0.05
"""Largest distance between the end of one route step and the start of the next, m."""


def stations_m(road: Road, spacing_m: float = SAMPLE_SPACING_M) -> np.ndarray:
    """Evenly spaced stations from 0 to the road's length inclusive, at most `spacing_m` apart."""
    if not spacing_m > 0:
        raise ValueError("spacing_m must be > 0")
    return np.linspace(0.0, road.length_m, max(2, math.ceil(road.length_m / spacing_m - 1e-9) + 1))


def _without_repeats(points: np.ndarray) -> np.ndarray:
    """Points with each one closer than 1 nm to the previous dropped (a polyline needs segments of length > 0)."""
    keep = np.concatenate([[True], np.hypot(*np.diff(points, axis=0).T) > 1e-9])
    return points[keep]


def reference_points(road: Road, spacing_m: float = SAMPLE_SPACING_M) -> np.ndarray:
    """Points [N, 2] (m) of a road's reference line from s = 0 to its end."""
    x, y, _ = reference_poses(road, stations_m(road, spacing_m))
    return np.column_stack([x, y])


def lane_points(network: Network, road_id: str, lane_id: int, spacing_m: float = SAMPLE_SPACING_M) -> np.ndarray:
    """Points [N, 2] (m) of a lane's centre line from s = 0 to the road's end."""
    road = _road(network, road_id)
    x, y, _ = lane_position(network, road.id, lane_id, stations_m(road, spacing_m))
    return np.column_stack([x, y])


def _road(network: Network, road_id: str) -> Road:
    road = network.roads.get(str(road_id))
    if road is None:
        raise UserInputError(f"{network.source or 'OpenDRIVE'}: no road {str(road_id)!r}")
    return road


def polyline(points: np.ndarray) -> PolylineSpec:
    """A vrusim polyline through `points` [N, 2]; fewer than two distinct points is a UserInputError."""
    distinct = _without_repeats(np.asarray(points, dtype=float))
    if len(distinct) < 2:
        raise UserInputError("an OpenDRIVE line of zero length cannot be a path")
    return PolylineSpec(tuple((float(x), float(y)) for x, y in distinct))


def along_s(road: Road, lane_id: int) -> bool:
    """Whether traffic in lane `lane_id` drives towards increasing s (right lanes under RHT)."""
    if lane_id == 0:
        raise UserInputError(f"road {road.id!r}: lane 0 (the centre lane) carries no traffic")
    return (lane_id < 0) == (road.rule == "RHT")


def route_polyline(
    network: Network, steps: Sequence[tuple[str, int]], spacing_m: float = SAMPLE_SPACING_M
) -> PolylineSpec:
    """The centre line of lanes `steps` [(road id, lane id), ...] chained in their direction of travel."""
    if not steps:
        raise UserInputError("a route needs at least one (road, lane)")
    parts: list[np.ndarray] = []
    for road_id, lane_id in steps:
        road = _road(network, road_id)
        points = lane_points(network, road.id, lane_id, spacing_m)
        points = points if along_s(road, lane_id) else points[::-1]
        if parts:
            gap = float(np.hypot(*(points[0] - parts[-1][-1])))
            if gap > MAX_GAP_M:
                raise UserInputError(
                    f"route: road {road.id!r} lane {lane_id} starts {gap:.3g} m from the end of the previous step"
                )
            points = points[1:]
        parts.append(points)
    return polyline(np.concatenate(parts))
