"""Exact contact geometry between an oriented rectangle (ego footprint) and circles (VRU footprints).

Batch-first and fully vectorised: rectangle quantities have shape ``[B]`` (one rectangle per variant),
circle quantities have shape ``[B, K]`` (K VRUs per variant). Rectangle arrays are broadcast against the
circle arrays by appending trailing axes, so ``[B]`` pairs with ``[B, K]`` (scalars also work).

Frames follow ISO 8855: x forward, y to the left. The rectangle's local frame has its origin at the
rectangle centre, x along the (unit) heading vector and y to its left. No trigonometric functions are
used; orientation is always given as a unit heading vector ``(heading_x, heading_y)``.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "IMPACT_SIDE_NAMES",
    "impact_side",
    "lateral_impact_fraction",
    "rectangle_circle_clearance",
    "to_local_frame",
]

FloatArray = NDArray[np.float64]

#: Names of the codes returned by :func:`impact_side` (index = code).
IMPACT_SIDE_NAMES: tuple[str, str, str, str] = ("front", "rear", "left", "right")


def _lift(a: ArrayLike, ndim: int) -> FloatArray:
    """Return ``a`` as float64, with trailing unit axes appended so that it has ``ndim`` dimensions.

    Scalars (0-d) are left as they are; ``[B]`` becomes ``[B, 1]`` for ``ndim == 2``.
    """
    arr = np.asarray(a, dtype=np.float64)
    if 0 < arr.ndim < ndim:
        arr = arr.reshape(arr.shape + (1,) * (ndim - arr.ndim))
    return arr


def _lift_all(ndim: int, *arrays: ArrayLike) -> list[FloatArray]:
    """:func:`_lift` applied to several per-rectangle arrays."""
    return [_lift(a, ndim) for a in arrays]


def _circle_arrays(*arrays: ArrayLike) -> list[FloatArray]:
    """Broadcast per-circle inputs to a common shape of at least one dimension (float64 views)."""
    return np.broadcast_arrays(*(np.atleast_1d(np.asarray(a, dtype=np.float64)) for a in arrays))


def _restore_shape(a: FloatArray, shape: tuple[int, ...]) -> FloatArray:
    """Undo the 1-d promotion of :func:`_circle_arrays` when all inputs were scalars."""
    return a.reshape(shape) if a.ndim == 1 and not shape and a.size == 1 else a


def _scratch(n: int, shape: tuple[int, ...]) -> list[FloatArray]:
    """``n`` uninitialised float64 work buffers of ``shape``, carved from a single allocation.

    One block instead of ``n`` separate arrays keeps allocator traffic (and page faults) low.
    """
    return list(np.empty((n, *shape)))


def _to_local_into(
    center_x: FloatArray,
    center_y: FloatArray,
    heading_x: FloatArray,
    heading_y: FloatArray,
    x: FloatArray,
    y: FloatArray,
    out_x: FloatArray,
    out_y: FloatArray,
    tmp: FloatArray,
) -> None:
    """Write the rectangle-frame coordinates of world points ``(x, y)`` into ``out_x, out_y``.

    Rectangle arrays must already be lifted to the points' number of dimensions; ``tmp`` is clobbered.
    """
    np.subtract(x, center_x, out=tmp)  # dx
    np.subtract(y, center_y, out=out_y)  # dy
    np.multiply(tmp, heading_x, out=out_x)
    tmp *= heading_y
    np.multiply(out_y, heading_y, out=out_y)  # dy * hy (dx * hy kept in tmp)
    out_x += out_y
    np.subtract(y, center_y, out=out_y)
    out_y *= heading_x
    out_y -= tmp


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
    shape = np.broadcast_shapes(np.shape(x), np.shape(y))
    px, py = _circle_arrays(x, y)
    rect = _lift_all(px.ndim, center_x, center_y, heading_x, heading_y)
    full = np.broadcast_shapes(px.shape, *(a.shape for a in rect))
    local_x, local_y, tmp = np.empty(full), np.empty(full), np.empty(full)
    _to_local_into(*rect, px, py, local_x, local_y, tmp)
    return _restore_shape(local_x, shape), _restore_shape(local_y, shape)


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
        ``(clearance, outline_x, outline_y)``, each [B, K]:

        * ``clearance`` m: distance from the circle centre to the filled rectangle minus the radius; it is
          <= 0 exactly when the bodies touch or overlap. For a centre inside the rectangle it is
          ``-(radius + depth)`` with depth the distance to the nearest edge (continuous, negative).
        * ``outline_x, outline_y`` m: point of the rectangle outline closest to the circle centre, in the
          rectangle's local frame (x forward along the heading, y left). A centre inside the rectangle is
          projected to its nearest edge (ties go to the front/rear edge).
    """
    shape = np.broadcast_shapes(np.shape(circle_x), np.shape(circle_y), np.shape(radius))
    px, py, r = _circle_arrays(circle_x, circle_y, radius)
    cx, cy, hx, hy, hl, hw = _lift_all(
        px.ndim, center_x, center_y, heading_x, heading_y, half_length, half_width
    )
    full = np.broadcast_shapes(px.shape, r.shape, cx.shape, cy.shape, hx.shape, hy.shape, hl.shape, hw.shape)
    lx, ly, clearance = np.empty(full), np.empty(full), np.empty(full)  # outputs
    ex, ey = _scratch(2, full)
    _to_local_into(cx, cy, hx, hy, px, py, lx, ly, ex)

    # Excess of |local coordinate| over the half extent (building blocks of the box signed distance).
    np.abs(lx, out=ex)
    ex -= hl
    np.abs(ly, out=ey)
    ey -= hw
    snap_x = ex >= ey  # front/rear edge at least as near as the side edge (used for interior points)
    depth = np.maximum(ex, ey, out=clearance)
    np.minimum(depth, 0.0, out=depth)  # -(distance to nearest edge) inside, 0 outside

    # Closest outline point: clamp to the filled rectangle, then push interior points onto the nearest
    # edge, i.e. add copysign(depth, coordinate) on the snapped axis (depth is 0 for exterior points).
    np.maximum(lx, -hl, out=lx)
    np.minimum(lx, hl, out=lx)
    np.maximum(ly, -hw, out=ly)
    np.minimum(ly, hw, out=ly)
    # Distance from an exterior centre to the rectangle (0 inside); ex/ey are consumed here.
    np.maximum(ex, 0.0, out=ex)
    ex *= ex
    np.maximum(ey, 0.0, out=ey)
    ey *= ey
    ex += ey
    np.sqrt(ex, out=ex)
    np.copysign(depth, lx, out=ey)
    ey *= snap_x
    lx += ey
    np.logical_not(snap_x, out=snap_x)
    np.copysign(depth, ly, out=ey)
    ey *= snap_x
    ly += ey

    clearance += ex  # depth + exterior distance
    clearance -= r
    return _restore_shape(clearance, shape), _restore_shape(lx, shape), _restore_shape(ly, shape)


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
