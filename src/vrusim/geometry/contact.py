"""Exact contact between an oriented rectangle (the ego) and circles (VRU footprints).

Batch-first: rectangles [B], circles [B, K] (a [B] rectangle array lines up with the first axis of [B, K]).
SI units, ISO 8855 local frame (x forward along the heading, y left). The geometry is written once as scalar
compiled functions (`clearance_local`) and applied over whole batches; no trigonometric calls.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from vrusim.kernels import batch_kernel, njit, prange

__all__ = [
    "IMPACT_SIDE_NAMES",
    "body_side",
    "clearance_local",
    "impact_location",
    "impact_side",
    "lateral_impact_fraction",
    "rectangle_circle_clearance",
    "to_local_frame",
]

FloatArray = NDArray[np.float64]

#: Names of the codes returned by :func:`impact_side` (index = code).
IMPACT_SIDE_NAMES: tuple[str, str, str, str] = ("front", "rear", "left", "right")


@njit(cache=True, inline="always")
def to_local(center_x, center_y, heading_x, heading_y, x, y):  # pragma: no cover (compiled)
    """World point -> rectangle frame (heading must be a unit vector)."""
    dx, dy = x - center_x, y - center_y
    return dx * heading_x + dy * heading_y, dy * heading_x - dx * heading_y


@njit(cache=True, inline="always")
def clearance_local(lx, ly, half_length, half_width, radius):  # pragma: no cover (compiled)
    """(clearance, outline x, outline y) of a circle at (lx, ly) in the rectangle frame.

    clearance = distance from the centre to the filled rectangle minus the radius (<= 0: touching or
    overlapping; -(radius + depth) for a centre inside, depth = distance to the nearest edge). The outline
    point is the point of the rectangle's boundary nearest the centre (interior centres go to the nearest
    edge; ties to the front/rear edge).
    """
    ex = abs(lx) - half_length
    ey = abs(ly) - half_width
    depth = min(max(ex, ey), 0.0)
    ox = min(max(lx, -half_length), half_length)
    oy = min(max(ly, -half_width), half_width)
    outside = math.sqrt(max(ex, 0.0) ** 2 + max(ey, 0.0) ** 2)
    if ex >= ey:
        ox += math.copysign(depth, ox)
    else:
        oy += math.copysign(depth, oy)
    return depth + outside - radius, ox, oy


def _lifted(rect: list, circles: list) -> tuple[list, tuple[int, ...]]:
    """Broadcast [B] rectangle arrays against [B, K] circle arrays; return flat float arrays and the shape."""
    circles = [np.asarray(a, dtype=np.float64) for a in circles]
    rect = [np.asarray(a, dtype=np.float64) for a in rect]
    ndim = max(1, *(a.ndim for a in circles))
    rect = [a.reshape(a.shape + (1,) * (ndim - a.ndim)) if 0 < a.ndim < ndim else a for a in rect]
    shape = np.broadcast_shapes(*(a.shape for a in rect + circles))
    flat = [np.ascontiguousarray(np.broadcast_to(a, shape)).ravel() for a in rect + circles]
    out_shape = shape if any(np.ndim(a) for a in rect + circles) else ()
    return flat, out_shape


@njit(cache=True)
def _clearance_many(cx, cy, hx, hy, hl, hw, px, py, r):  # pragma: no cover (compiled)
    n = px.shape[0]
    out = np.empty((3, n))
    for i in range(n):
        lx, ly = to_local(cx[i], cy[i], hx[i], hy[i], px[i], py[i])
        out[0, i], out[1, i], out[2, i] = clearance_local(lx, ly, hl[i], hw[i], r[i])
    return out


@njit(cache=True)
def _local_many(cx, cy, hx, hy, px, py):  # pragma: no cover (compiled)
    n = px.shape[0]
    out = np.empty((2, n))
    for i in range(n):
        out[0, i], out[1, i] = to_local(cx[i], cy[i], hx[i], hy[i], px[i], py[i])
    return out


def to_local_frame(
    center_x: ArrayLike,
    center_y: ArrayLike,
    heading_x: ArrayLike,
    heading_y: ArrayLike,
    x: ArrayLike,
    y: ArrayLike,
) -> tuple[FloatArray, FloatArray]:
    """Express world points ``(x, y)`` [B, K] m in the rectangle frame given by centre/heading [B].

    Returns ``(local_x, local_y)`` [B, K] m: local_x along the heading, local_y to its left.
    The heading vector must be unit length (it is not re-normalised).
    """
    flat, shape = _lifted([center_x, center_y, heading_x, heading_y], [x, y])
    out = _local_many(*flat)
    return out[0].reshape(shape), out[1].reshape(shape)


def rectangle_circle_clearance(
    center_x: ArrayLike,
    center_y: ArrayLike,
    heading_x: ArrayLike,
    heading_y: ArrayLike,
    half_length: ArrayLike,
    half_width: ArrayLike,
    circle_x: ArrayLike,
    circle_y: ArrayLike,
    radius: ArrayLike,
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Signed clearance between oriented rectangles [B] and circles [B, K].

    Args:
        center_x, center_y: rectangle centre [B], m (world frame).
        heading_x, heading_y: unit heading vector of the rectangle's length axis [B] (not re-normalised).
        half_length, half_width: rectangle half extents [B], m (>= 0).
        circle_x, circle_y: circle centres [B, K], m (world frame).
        radius: circle radii [B, K], m (>= 0).

    Returns:
        ``(clearance, outline_x, outline_y)``, each [B, K] m, as defined in :func:`clearance_local`
        (outline point in the rectangle's local frame).
    """
    flat, shape = _lifted(
        [center_x, center_y, heading_x, heading_y, half_length, half_width], [circle_x, circle_y, radius]
    )
    out = _clearance_many(*flat)
    return out[0].reshape(shape), out[1].reshape(shape), out[2].reshape(shape)


def _lift(a: ArrayLike, ndim: int) -> FloatArray:
    """``a`` as float64 with trailing unit axes appended up to ``ndim`` dimensions (scalars unchanged)."""
    arr = np.asarray(a, dtype=np.float64)
    if 0 < arr.ndim < ndim:
        arr = arr.reshape(arr.shape + (1,) * (ndim - arr.ndim))
    return arr


def impact_side(
    outline_x: ArrayLike, outline_y: ArrayLike, half_length: ArrayLike, half_width: ArrayLike
) -> NDArray[np.int8]:
    """Edge code of outline points [B, K] (local frame, m) of rectangles with half extents [B], m.

    Returns int8 [B, K]: 0 front, 1 rear, 2 left, 3 right (see :data:`IMPACT_SIDE_NAMES`). Corners are
    assigned to front/rear. For points not exactly on the outline, the edge whose line is exceeded the
    most (or, inside, is nearest) is chosen.
    """
    ox = np.asarray(outline_x, dtype=np.float64)
    oy = np.asarray(outline_y, dtype=np.float64)
    nd = max(ox.ndim, oy.ndim)
    ex = np.abs(ox) - _lift(half_length, nd)
    ey = np.abs(oy) - _lift(half_width, nd)
    longitudinal = np.where(ox < 0.0, np.int8(1), np.int8(0))
    lateral = np.where(oy < 0.0, np.int8(3), np.int8(2))
    return np.where(ex >= ey, longitudinal, lateral).astype(np.int8, copy=False)


def lateral_impact_fraction(outline_y: ArrayLike, half_width: ArrayLike) -> FloatArray:
    """Lateral position of outline points along the front edge as a fraction of vehicle width.

    Euro NCAP convention: 0.0 at the right edge (y = -half_width), 1.0 at the left edge (y = +half_width),
    i.e. ``(outline_y + half_width) / (2 * half_width)`` clipped to [0, 1]. ``outline_y`` [B, K] m,
    ``half_width`` [B] m. A zero-width rectangle gives 0.5.
    """
    oy = np.asarray(outline_y, dtype=np.float64)
    hw = _lift(half_width, oy.ndim)
    width = 2.0 * hw
    safe_width = np.where(width > 0.0, width, 1.0)
    frac = (oy + hw) / safe_width
    frac = np.where(width > 0.0, frac, 0.5)
    return np.clip(frac, 0.0, 1.0)


_MIRRORED_SIDE = np.array([1, 0, 3, 2], dtype=np.int8)
"""Side codes of the body mirrored front to back (a reversing ego): front <-> rear, left <-> right."""


def body_side(side: ArrayLike, reverse: ArrayLike) -> NDArray[np.int8]:
    """Side codes (:data:`IMPACT_SIDE_NAMES`) [B] of the simulated frame as sides of the real body: mirrored
    (front <-> rear, left <-> right) where `reverse` [B] (the simulated frame of a reversing ego is the body
    mirrored front to back, docs/models.md "Reversing")."""
    codes = np.asarray(side, dtype=np.int8)
    return np.where(np.asarray(reverse, dtype=bool), _MIRRORED_SIDE[codes], codes).astype(np.int8, copy=False)


def impact_location(
    side: ArrayLike, local_x: ArrayLike, local_y: ArrayLike, half_length: ArrayLike, half_width: ArrayLike,
    reverse: ArrayLike,
) -> FloatArray:  # fmt: skip
    """Euro NCAP impact location (LSC26 §1.2.2, FC26 "Impact location") of a VRU reference point [B]: on the
    front or rear (`side` 0, 1 of the real body, :func:`body_side`), the fraction of the vehicle width, 0 at the
    right edge, 1 at the left; on a side (2, 3), the fraction of the vehicle length, 0 at the rearmost point,
    1 at the most forward. `local_x`, `local_y` [B] m are the point in the simulated vehicle frame (mirrored
    into the body frame where `reverse`). Not clipped: a value outside [0, 1] means the point lay beyond a
    corner (a corner hit)."""
    sign = np.where(np.asarray(reverse, dtype=bool), -1.0, 1.0)
    bx, by = sign * np.asarray(local_x, dtype=float), sign * np.asarray(local_y, dtype=float)
    hl, hw = np.asarray(half_length, dtype=float), np.asarray(half_width, dtype=float)
    codes = np.asarray(side)
    return np.where(codes >= 2, (bx + hl) / (2.0 * hl), (by + hw) / (2.0 * hw))


@batch_kernel
def clearance_batch(cx, cy, hx, hy, hl, hw, px, py, r, out):  # pragma: no cover (compiled)
    """Engine fast path: rectangles [B], circles [B, K] -> out [3, B, K] = clearance, outline x, outline y."""
    for b in prange(px.shape[0]):
        clearance_variant(b, cx, cy, hx, hy, hl, hw, px, py, r, out)


@njit(cache=True, inline="always")
def clearance_variant(b, cx, cy, hx, hy, hl, hw, px, py, r, out):  # pragma: no cover (compiled)
    """`clearance_batch` for variant b."""
    K = px.shape[1]
    for k in range(K):
        lx, ly = to_local(cx[b], cy[b], hx[b], hy[b], px[b, k], py[b, k])
        out[0, b, k], out[1, b, k], out[2, b, k] = clearance_local(lx, ly, hl[b], hw[b], r[b, k])
