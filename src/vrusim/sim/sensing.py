"""Onboard sector sensor.

The field of view is a circular sector with its apex at the centre of the front bumper, centred on the ego
heading, of radius `range_m` and full opening angle `fov_deg`. A VRU counts as perceived in a step when any
part of its footprint circle lies inside the sector, i.e. when the distance from its centre to the (filled)
sector is at most its radius. The sensor is ideal: a perceived VRU's true position and velocity are reported.
"""

from __future__ import annotations

import numpy as np


def distance_to_sector(apex_x, apex_y, heading_x, heading_y, range_m, cos_half, sin_half, px, py) -> np.ndarray:
    """Distance (m) from points [B, K] to the filled sectors [B] (0 inside). No trigonometric calls."""
    dx = px - apex_x[:, None]
    dy = py - apex_y[:, None]
    hx, hy = heading_x[:, None], heading_y[:, None]
    along = dx * hx + dy * hy
    across = np.abs(hx * dy - hy * dx)
    dist = np.sqrt(dx * dx + dy * dy)
    radial = np.maximum(dist - range_m[:, None], 0.0)
    c, s = cos_half[:, None], sin_half[:, None]
    # nearest point on the boundary segment on the point's side (the sector is mirror-symmetric)
    proj = np.clip(along * c + across * s, 0.0, range_m[:, None])
    ex, ey = along - proj * c, across - proj * s
    edge = np.sqrt(ex * ex + ey * ey)
    inside_angle = along >= dist * c
    return np.where(inside_angle, radial, edge)


def perceived(apex_x, apex_y, heading_x, heading_y, range_m, cos_half, sin_half, px, py, radius, enabled):
    """Which VRU footprints [B, K] intersect each ego's sensor sector."""
    gap = distance_to_sector(apex_x, apex_y, heading_x, heading_y, range_m, cos_half, sin_half, px, py)
    return (gap <= radius) & enabled[:, None]
