"""Onboard sector sensor.

The field of view is a circular sector with its apex at the centre of the front bumper, centred on the ego
heading, of radius `range_m` and full opening angle `fov_deg`. A VRU counts as perceived in a step when any
part of its footprint circle lies inside the sector, i.e. when the distance from its centre to the (filled)
sector is at most its radius, and some part of the footprint is in the apex's line of sight past the
variant's static obstacles (`sim/sensing/occlusion.py`). At night the packed range is already reduced
(`Sensor.effective_range_m`). This is geometric visibility only: what the sensor reports (latency, missed
detections, noise) is decided by the sensor model (`sim/sensing/sensor_model.py`).
"""

from __future__ import annotations

import numpy as np

from vrusim.kernels import batch_kernel, njit, prange
from vrusim.sim.sensing.occlusion import ObstacleArrays, occlude

FAR_FACTOR = 1.0 + 1e-6
"""Margin of the far screen in `perceived_variant`: the distance to the sector is at least the distance to its
circle, and this relative margin (sqrt: 5e-7) far exceeds the rounding of either, so the screen never changes a
result."""


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


@njit(cache=True, inline="always")
def perceived_variant(
    b, apex_x, apex_y, hx, hy, range_m, cos_half, sin_half, enabled, px, py, radius, out
):  # pragma: no cover (compiled)
    """`out[b, :]`: which VRUs of variant b its sector covers (before occlusion).

    A footprint clearly beyond the sector's circle (squared distance above `FAR_FACTOR` times the squared reach,
    range plus radius) is not covered whatever its bearing, and skips the exact distance.
    """
    for k in range(px.shape[1]):
        dx, dy = px[b, k] - apex_x[b], py[b, k] - apex_y[b]
        reach = range_m[b] + radius[b, k]
        out[b, k] = (
            enabled[b]
            and not dx * dx + dy * dy > FAR_FACTOR * (reach * reach)
            and sector_distance(dx, dy, hx[b], hy[b], range_m[b], cos_half[b], sin_half[b]) <= radius[b, k]
        )


@batch_kernel
def _perceived(
    apex_x, apex_y, hx, hy, range_m, cos_half, sin_half, enabled, px, py, radius, out
):  # pragma: no cover (compiled)
    for b in prange(px.shape[0]):
        perceived_variant(b, apex_x, apex_y, hx, hy, range_m, cos_half, sin_half, enabled, px, py, radius, out)


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
    if params.obstacles.x_m.shape[1]:  # some variant has obstacles (M > 0); the others are skipped inside
        occlude(params.size, front_x, front_y, vrus.x_m, vrus.y_m, params.vru_radius_m, *params.obstacles, out)
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


def perceived(
    apex_x,
    apex_y,
    heading_x,
    heading_y,
    range_m,
    cos_half,
    sin_half,
    px,
    py,
    radius,
    enabled,
    obstacles: ObstacleArrays | None = None,
):
    """Which VRU footprints [B, K] intersect each ego's sensor sector and are in its line of sight.

    `obstacles` (one row per variant, see `occlusion.pack_obstacles`) block the line of sight; None: none.
    """
    gap = distance_to_sector(apex_x, apex_y, heading_x, heading_y, range_m, cos_half, sin_half, px, py)
    seen = (gap <= radius) & np.asarray(enabled)[:, None]
    if obstacles is None or not np.any(obstacles.count):
        return seen
    B = gap.shape[0]

    def rows(a) -> np.ndarray:  # [B, K] float, contiguous
        return np.ascontiguousarray(np.broadcast_to(np.asarray(a, dtype=float), gap.shape)).reshape(B, -1)

    apex = [np.ascontiguousarray(np.broadcast_to(_batch(a), (B,))) for a in (apex_x, apex_y)]
    out = np.ascontiguousarray(seen).reshape(B, -1)
    count = np.ascontiguousarray(obstacles.count, dtype=np.int64)
    boxes = [np.ascontiguousarray(a, dtype=float) for a in obstacles[1:]]
    occlude(B, *apex, rows(px), rows(py), rows(radius), count, *boxes, out)
    return out.reshape(gap.shape)
