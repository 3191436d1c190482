"""OpenDRIVE road and lane positions to world coordinates: lane offset, lane widths, lane borders and centres.

A road position (road, s, t) lies t metres left of the reference line at station s (right: t < 0). Lane
borders count outward from the centre lane, which lies at the lane offset: the outer border of left lane n
is offset + w1 + ... + wn, of right lane -n is offset - (w-1 + ... + w-n); a lane's centre is halfway
between its borders (ASAM OpenDRIVE 1.6 / 1.8, chapter "Lanes"). Every polynomial is evaluated
from the last record starting at or before the station; before the first one it is 0. Heading: the
reference line's at s (the direction of the s axis). Lengths in m, angles in rad.
"""

from __future__ import annotations

import numpy as np

from vrusim.errors import UserInputError
from vrusim.formats.xodr_geometry import Poses, checked_stations, reference_poses
from vrusim.formats.xodr_model import Cubic, Network, Road


def cubic_at(records: tuple[Cubic, ...], s_m: np.ndarray, origin_m: float = 0.0) -> np.ndarray:
    """The piecewise cubic of `records` at stations `s_m` (record stations measured from `origin_m`)."""
    s = np.asarray(s_m, dtype=float)
    if not records:
        return np.zeros(s.shape)
    starts = np.array([record.s_m for record in records]) + origin_m
    index = np.searchsorted(starts, s, side="right") - 1
    table = np.array([[r.a, r.b, r.c, r.d] for r in records])[np.maximum(index, 0)]
    ds = s - starts[np.maximum(index, 0)]
    value = table[:, 0] + ds * (table[:, 1] + ds * (table[:, 2] + ds * table[:, 3]))
    return np.where(index >= 0, value, 0.0)


def lane_offset_m(road: Road, s_m: np.ndarray) -> np.ndarray:
    """The lateral shift of the centre lane from the reference line (`<laneOffset>`), m."""
    return cubic_at(road.lane_offsets, np.asarray(s_m, dtype=float))


def lane_borders_t(road: Road, lane_id: int, s_m: np.ndarray | float) -> tuple[np.ndarray, np.ndarray]:
    """t (m) of the inner and outer border of lane `lane_id` at stations `s_m` (lane 0: both at the offset)."""
    s = checked_stations(road, s_m)
    starts = np.array([section.s_m for section in road.sections])
    which = np.clip(np.searchsorted(starts, s, side="right") - 1, 0, len(starts) - 1)
    inner = lane_offset_m(road, s)
    outer = inner.copy()
    sign = 1.0 if lane_id > 0 else -1.0
    for number in np.unique(which):
        section = road.sections[number]
        lanes = section.left if lane_id > 0 else section.right
        if abs(lane_id) > len(lanes):
            raise UserInputError(f"road {road.id!r}: no lane {lane_id} in the lane section at s = {section.s_m:g} m")
        mask = which == number
        for lane in lanes[: abs(lane_id)]:
            width = sign * cubic_at(lane.widths, s[mask], section.s_m)
            inner[mask] = outer[mask]
            outer[mask] = outer[mask] + width
    return inner, outer


def lane_centre_t(road: Road, lane_id: int, s_m: np.ndarray | float) -> np.ndarray:
    """t (m) of the centre of lane `lane_id` at stations `s_m`."""
    inner, outer = lane_borders_t(road, lane_id, s_m)
    return 0.5 * (inner + outer)


def road_to_world(road: Road, s_m: np.ndarray | float, t_m: np.ndarray | float) -> Poses:
    """World pose of road positions (s, t): the reference point moved t to its left; heading of the s axis."""
    x, y, heading = reference_poses(road, s_m)
    t = np.broadcast_to(np.asarray(t_m, dtype=float), x.shape)
    return x - t * np.sin(heading), y + t * np.cos(heading), heading


def _road(network: Network, road_id: str) -> Road:
    try:
        return network.roads[str(road_id)]
    except KeyError:
        raise UserInputError(f"{network.source or 'OpenDRIVE'}: no road {str(road_id)!r}") from None


def road_position(network: Network, road_id: str, s_m: np.ndarray | float, t_m: np.ndarray | float = 0.0) -> Poses:
    """World pose of a road position (OpenSCENARIO RoadPosition) on `network`."""
    return road_to_world(_road(network, road_id), s_m, t_m)


def lane_position(
    network: Network, road_id: str, lane_id: int, s_m: np.ndarray | float, offset_m: np.ndarray | float = 0.0
) -> Poses:
    """World pose of a lane position (OpenSCENARIO LanePosition): `offset_m` left of lane `lane_id`'s centre."""
    road = _road(network, road_id)
    s = checked_stations(road, s_m)
    return road_to_world(road, s, lane_centre_t(road, lane_id, s) + np.asarray(offset_m, dtype=float))
