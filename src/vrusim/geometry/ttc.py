"""Exact 2-D time-to-collision between an oriented rectangle (ego) and circles (VRUs).

Both bodies move with constant velocity and the rectangle keeps its current heading. In the rectangle
frame the circle centre follows the ray ``p + w t``; the collision set is the rectangle dilated by the
circle radius (a rounded rectangle). The TTC is the ray's earliest entry time into that set, found
with a slab test against the rounded rectangle's bounding box followed by a single ray/disk test when
the entry point lies in a corner square (whose inner sides lie inside the corner disk, so the ray can only
reach the set there through the disk). Batch-first (rectangle [B], circles [B, K]), no trigonometric
functions, never NaN for finite inputs.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from vrusim.geometry.contact import _lifted, to_local
from vrusim.kernels import batch_kernel, njit, prange

__all__ = ["time_to_collision", "ttc_local"]

FloatArray = NDArray[np.float64]

_CORNER_TOL = 1e-10
"""Entry points closer than this (m) to a face strip count as face entries (keeps r = 0 corner hits)."""


@njit(cache=True, inline="always")
def _slab(p, w, half):  # pragma: no cover (compiled)
    """Entry and exit time of p + w t in |x| <= half (closed); (inf, -inf) when never inside."""
    if w == 0.0:
        return (-np.inf, np.inf) if abs(p) <= half else (np.inf, -np.inf)
    edge = math.copysign(half, w)
    return (-edge - p) / w, (edge - p) / w


@njit(cache=True, inline="always")
def ttc_local(px, py, wx, wy, half_length, half_width, radius, horizon):  # pragma: no cover (compiled)
    """TTC (s) of a circle at p moving at w relative to a rectangle, both in the rectangle frame."""
    x_in, x_out = _slab(px, wx, half_length + radius)
    y_in, y_out = _slab(py, wy, half_width + radius)
    t0 = max(x_in, y_in, 0.0)
    if min(x_out, y_out) < t0 or t0 == np.inf:
        return np.inf
    qx, qy = px + wx * t0, py + wy * t0
    t = t0
    if abs(qx) > half_length + _CORNER_TOL and abs(qy) > half_width + _CORNER_TOL:
        # ray / corner-disk entry: a t^2 + 2 b t + c = 0, root c / (sqrt(b^2 - a c) - b), stable for a = 0
        dx, dy = px - math.copysign(half_length, qx), py - math.copysign(half_width, qy)
        c = dx * dx + dy * dy - radius * radius
        if c <= 0.0:
            return 0.0
        b = min(dx * wx + dy * wy, 0.0)
        disc = b * b - (wx * wx + wy * wy) * c
        if disc < 0.0:
            return np.inf
        denominator = math.sqrt(disc) - b
        if denominator <= 0.0:
            return np.inf
        t = c / denominator
    return t if t <= horizon else np.inf


@njit(cache=True)
def _ttc_many(cx, cy, hx, hy, hl, hw, evx, evy, qx, qy, r, vx, vy, horizon):  # pragma: no cover (compiled)
    n = qx.shape[0]
    out = np.empty(n)
    for i in range(n):
        px, py = to_local(cx[i], cy[i], hx[i], hy[i], qx[i], qy[i])
        wx, wy = to_local(evx[i], evy[i], hx[i], hy[i], vx[i], vy[i])
        out[i] = ttc_local(px, py, wx, wy, hl[i], hw[i], r[i], horizon)
    return out


def time_to_collision(
    center_x: ArrayLike,
    center_y: ArrayLike,
    heading_x: ArrayLike,
    heading_y: ArrayLike,
    half_length: ArrayLike,
    half_width: ArrayLike,
    ego_vx: ArrayLike,
    ego_vy: ArrayLike,
    circle_x: ArrayLike,
    circle_y: ArrayLike,
    radius: ArrayLike,
    vru_vx: ArrayLike,
    vru_vy: ArrayLike,
    horizon: float = np.inf,
) -> FloatArray:
    """Time until the circles [B, K] first touch the moving rectangle [B] under constant velocities.

    Args:
        center_x, center_y: rectangle centre [B], m (world frame).
        heading_x, heading_y: unit heading vector of the rectangle [B] (not re-normalised; kept fixed).
        half_length, half_width: rectangle half extents [B], m (>= 0).
        ego_vx, ego_vy: rectangle velocity [B], m/s (world frame).
        circle_x, circle_y: circle centres [B, K], m (world frame).
        radius: circle radii [B, K], m (>= 0).
        vru_vx, vru_vy: circle velocities [B, K], m/s (world frame).
        horizon: s; collision times strictly greater than this are reported as ``inf``.

    Returns:
        TTC [B, K] in s, >= 0: 0 if already touching/overlapping, ``inf`` if no contact ever occurs
        (or only after ``horizon``).
    """
    flat, shape = _lifted(
        [center_x, center_y, heading_x, heading_y, half_length, half_width, ego_vx, ego_vy],
        [circle_x, circle_y, radius, vru_vx, vru_vy],
    )
    return _ttc_many(*flat, float(horizon)).reshape(shape)


@batch_kernel
def ttc_batch(cx, cy, hx, hy, hl, hw, speed, qx, qy, r, vx, vy, out):  # pragma: no cover (compiled)
    """Engine fast path: rectangles [B] moving at `speed` along their heading, circles [B, K]
    -> out = TTC [B, K] s (no horizon)."""
    for b in prange(qx.shape[0]):
        ttc_variant(b, cx, cy, hx, hy, hl, hw, speed, qx, qy, r, vx, vy, out)


@njit(cache=True, inline="always")
def ttc_variant(b, cx, cy, hx, hy, hl, hw, speed, qx, qy, r, vx, vy, out):  # pragma: no cover (compiled)
    """`ttc_batch` for variant b."""
    K = qx.shape[1]
    evx, evy = speed[b] * hx[b], speed[b] * hy[b]
    for k in range(K):
        px, py = to_local(cx[b], cy[b], hx[b], hy[b], qx[b, k], qy[b, k])
        wx, wy = to_local(evx, evy, hx[b], hy[b], vx[b, k], vy[b, k])
        out[b, k] = ttc_local(px, py, wx, wy, hl[b], hw[b], r[b, k], np.inf)
