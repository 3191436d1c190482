"""Onboard sector sensor.

The field of view is a circular sector with its apex at the centre of the front bumper, centred on the ego
heading, of radius `range_m` and full opening angle `fov_deg`. A VRU counts as perceived in a step when any
part of its footprint circle lies inside the sector, i.e. when the distance from its centre to the (filled)
sector is at most its radius. The sensor is ideal: a perceived VRU's true position, velocity and acceleration
are reported.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from vrusim.sim.kernels import batch_kernel


@njit(cache=True, inline="always")
def sector_distance(dx, dy, hx, hy, range_m, cos_half, sin_half):  # pragma: no cover (compiled)
    """Distance (m) from a point at offset (dx, dy) from the apex to the filled sector (0 inside)."""
    along = dx * hx + dy * hy
    across = abs(hx * dy - hy * dx)
    dist = np.sqrt(dx * dx + dy * dy)
    if along >= dist * cos_half:  # inside the opening angle
        return max(dist - range_m, 0.0)
    # nearest point on the boundary segment on the point's side (the sector is mirror-symmetric)
    proj = min(max(along * cos_half + across * sin_half, 0.0), range_m)
    ex, ey = along - proj * cos_half, across - proj * sin_half
    return np.sqrt(ex * ex + ey * ey)


@njit(cache=True)
def _distances(apex_x, apex_y, hx, hy, range_m, cos_half, sin_half, px, py):  # pragma: no cover (compiled)
    B, K = px.shape
    out = np.empty((B, K))
    for b in range(B):
        for k in range(K):
            out[b, k] = sector_distance(
                px[b, k] - apex_x[b], py[b, k] - apex_y[b], hx[b], hy[b], range_m[b], cos_half[b], sin_half[b]
            )
    return out


@batch_kernel
def _perceived(
    apex_x, apex_y, hx, hy, range_m, cos_half, sin_half, enabled, px, py, radius, out
):  # pragma: no cover (compiled)
    B, K = px.shape
    for b in prange(B):
        for k in range(K):
            out[b, k] = (
                enabled[b]
                and sector_distance(
                    px[b, k] - apex_x[b],
                    py[b, k] - apex_y[b],
                    hx[b],
                    hy[b],
                    range_m[b],
                    cos_half[b],
                    sin_half[b],
                )
                <= radius[b, k]
            )


def sense(params, front_x: np.ndarray, front_y: np.ndarray, ego, vrus) -> np.ndarray:
    """Which VRUs [B, K] each ego's sensor perceives now (engine fast path of `perceived`)."""
    out = np.empty(vrus.x_m.shape, dtype=bool)
    _perceived(
        params.size,
        front_x,
        front_y,
        ego.heading_x,
        ego.heading_y,
        params.sensor_range_m,
        params.sensor_cos_half,
        params.sensor_sin_half,
        params.sensor_enabled,
        vrus.x_m,
        vrus.y_m,
        params.vru_radius_m,
        out,
    )
    return out


def _batch(a) -> np.ndarray:
    return np.atleast_1d(np.asarray(a, dtype=float))


def distance_to_sector(apex_x, apex_y, heading_x, heading_y, range_m, cos_half, sin_half, px, py) -> np.ndarray:
    """Distance (m) from points [B, K] to the filled sectors [B] (0 inside). No trigonometric calls."""
    apex = [_batch(a) for a in (apex_x, apex_y, heading_x, heading_y, range_m, cos_half, sin_half)]
    px, py = np.asarray(px, dtype=float), np.asarray(py, dtype=float)
    shape = np.broadcast_shapes(px.shape, py.shape, (apex[0].shape[0], 1))
    px2 = np.ascontiguousarray(np.broadcast_to(px, shape)).reshape(shape[0], -1)
    py2 = np.ascontiguousarray(np.broadcast_to(py, shape)).reshape(shape[0], -1)
    return _distances(*apex, px2, py2).reshape(shape)


def perceived(apex_x, apex_y, heading_x, heading_y, range_m, cos_half, sin_half, px, py, radius, enabled):
    """Which VRU footprints [B, K] intersect each ego's sensor sector."""
    gap = distance_to_sector(apex_x, apex_y, heading_x, heading_y, range_m, cos_half, sin_half, px, py)
    return (gap <= radius) & np.asarray(enabled)[:, None]
