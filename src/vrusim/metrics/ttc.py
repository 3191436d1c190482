"""Exact 2-D time-to-collision between an oriented rectangle (ego) and circles (VRUs).

Both bodies move with constant velocity and the rectangle keeps its current heading. In the rectangle
frame the circle centre follows the ray ``p + w t``; the collision set is the rectangle dilated by the
circle radius (a rounded rectangle). The TTC is the ray's earliest entry time into that set, found
with a slab test against the rounded rectangle's bounding box followed by a single ray/disk test when
the entry point lies in a corner square. Fully vectorised, batch-first (rectangle [B], circles [B, K]),
no trigonometric functions, never NaN for finite inputs.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from vrusim.sim.contact import _circle_arrays, _lift_all, _restore_shape, _scratch, _to_local_into

__all__ = ["time_to_collision"]

FloatArray = NDArray[np.float64]

_TINY = float(np.finfo(np.float64).tiny)  # smallest normal float64
#: Entry points closer than this (m) to a face strip are not treated as corner entries (rounding guard).
_CORNER_TOL = 1e-10


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
    shape = np.broadcast_shapes(*(np.shape(a) for a in (circle_x, circle_y, radius, vru_vx, vru_vy)))
    qx, qy, r, vx, vy = _circle_arrays(circle_x, circle_y, radius, vru_vx, vru_vy)
    rect = _lift_all(
        qx.ndim, center_x, center_y, heading_x, heading_y, half_length, half_width, ego_vx, ego_vy
    )
    full = np.broadcast_shapes(qx.shape, r.shape, vx.shape, vy.shape, *(a.shape for a in rect))
    cx, cy, hx, hy, hl, hw, evx, evy = rect
    t_enter = np.empty(full)  # becomes the output
    px, py, wx, wy, s1, s2, tmp = _scratch(7, full)
    _to_local_into(cx, cy, hx, hy, qx, qy, px, py, s1)
    # Relative velocity of the circle w.r.t. the rectangle, rotated into the rectangle frame.
    _to_local_into(evx, evy, hx, hy, vx, vy, wx, wy, s1)

    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        # Slab test against the bounding box |x| <= hl + r, |y| <= hw + r of the rounded rectangle. With
        # sa = copysign(a, w) the slab |p + w t| <= a is entered at -(p + sa) / w and left at (sa - p) / w.
        # For w == +-0 these are -inf/+inf inside the slab, an empty or never-entered interval outside,
        # and NaN (0/0) exactly on the slab boundary; fmin/fmax ignore that NaN, i.e. treat the axis as
        # unconstrained, which is correct for a point resting on the (closed) slab boundary.
        np.add(r, hl, out=s1)
        np.copysign(s1, wx, out=s1)
        np.add(px, s1, out=t_enter)  # holds -(entry time) until negated below
        t_enter /= wx
        np.subtract(s1, px, out=s1)
        s1 /= wx  # exit time of the x slab
        np.add(r, hw, out=s2)
        np.copysign(s2, wy, out=s2)
        np.add(py, s2, out=tmp)
        tmp /= wy
        np.fmin(t_enter, tmp, out=t_enter)
        np.subtract(s2, py, out=s2)
        s2 /= wy  # exit time of the y slab
        np.fmin(t_enter, 0.0, out=t_enter)
        t0 = np.subtract(0.0, t_enter, out=t_enter)  # box entry time (+0 if inside), never NaN, maybe +inf
        t_exit = np.fmin(s1, s2, out=s1)  # NaN only when unconstrained on both axes
        miss = t_exit < t0

        # Entry point q = p + w t0. Unless it lies in a corner square (|qx| > hl and |qy| > hw) it is on
        # the rounded rectangle and t0 is the answer. In a corner square the ray can only reach the rest
        # of the set through that corner's disk (the square's inner sides lie inside the disk). Entry points
        # within _CORNER_TOL of a face strip count as face entries so that r = 0 corner hits survive rounding.
        # (t0 = +inf only occurs with a zero velocity component, making q NaN there: no corner.)
        np.multiply(wx, t0, out=s2)
        s2 += px
        np.abs(s2, out=tmp)
        corner = tmp > hl + _CORNER_TOL
        np.copysign(hl, s2, out=s2)
        px -= s2  # dx: circle centre relative to the corner
        np.multiply(wy, t0, out=s2)
        s2 += py
        np.abs(s2, out=tmp)
        corner &= tmp > hw + _CORNER_TOL
        np.copysign(hw, s2, out=s2)
        py -= s2  # dy

        # Ray/disk entry: |d + w t|^2 = r^2  ->  a t^2 + 2 b t + c = 0 with b clamped to <= 0 (receding
        # rays then get a negative discriminant when outside the disk). The entry root
        # (-b - sqrt(b^2 - a c)) / a is evaluated as c / (sqrt(b^2 - a c) - b): stable and valid for a = 0.
        b = np.multiply(px, wx, out=s1)
        np.multiply(py, wy, out=s2)
        b += s2
        np.minimum(b, 0.0, out=b)
        c = px
        c *= px
        py *= py
        c += py
        np.multiply(r, r, out=py)
        c -= py
        a = wx
        a *= wx
        wy *= wy
        a += wy
        a *= c
        disc = np.multiply(b, b, out=s2)
        disc -= a
        np.sqrt(disc, out=disc)  # NaN if the ray misses the disk
        disc -= b  # >= 0, or NaN; 0 only when not approaching (a c = 0, b = 0)
        c -= _TINY  # so that c = 0 (touching) over a zero denominator gives -inf -> 0 instead of NaN
        t_disk = np.divide(c, disc, out=c)
        np.fmin(t_disk, np.inf, out=t_disk)  # NaN (miss) -> inf
        np.maximum(t_disk, 0.0, out=t_disk)  # centre already inside the disk -> 0

        ttc = t0
        np.putmask(ttc, corner, t_disk)
        if horizon < np.inf:
            miss |= ttc > horizon
        np.putmask(ttc, miss, np.inf)
    return _restore_shape(ttc, shape)
