"""Line-of-sight occlusion of the onboard sensor by static obstacles (oriented rectangles).

A VRU footprint circle is visible from the sensor apex when at least one of `RAYS` sight lines reaches it
without crossing an obstacle. The rays span the circle's silhouette as seen from the apex: equally spaced
in angle over ±asin(r/d) around the direction to its centre (d = distance apex–centre), each ending where
it first meets the circle (the two outer rays end at the tangent points). An apex inside the circle sees
it. Obstacles are closed rectangles; a ray that touches one is blocked. See docs/models.md.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import NamedTuple

import numpy as np

from vrusim.kernels import batch_kernel, njit, prange

RAYS = 7
"""Sight lines per VRU footprint (odd); adjacent rays are 2·asin(r/d) / (RAYS − 1) apart."""
_PAIRS = (RAYS - 1) // 2

_FAR_M = 1.0e7
"""Centre coordinate of a padding slot (a zero-size box 10,000 km away; never read, harmless if it were)."""


class ObstacleArrays(NamedTuple):
    """Obstacles of a batch: `count` [B] (int64); the others [B, M], slots beyond `count[b]` are padding."""

    count: np.ndarray
    x_m: np.ndarray
    y_m: np.ndarray
    heading_x: np.ndarray
    heading_y: np.ndarray
    half_length_m: np.ndarray
    half_width_m: np.ndarray


def pack_obstacles(per_variant: Sequence[Sequence]) -> ObstacleArrays:
    """Pack each variant's obstacles (objects with `centre`, `length_m`, `width_m`) into `ObstacleArrays`."""
    B = len(per_variant)
    M = max((len(boxes) for boxes in per_variant), default=0)
    count = np.array([len(boxes) for boxes in per_variant], dtype=np.int64)
    x, y = np.full((B, M), _FAR_M), np.full((B, M), _FAR_M)
    hx, hy = np.ones((B, M)), np.zeros((B, M))
    half_l, half_w = np.zeros((B, M)), np.zeros((B, M))
    for b, boxes in enumerate(per_variant):
        for m, box in enumerate(boxes):
            heading = np.radians(box.centre.heading_deg)
            x[b, m], y[b, m] = box.centre.x_m, box.centre.y_m
            hx[b, m], hy[b, m] = np.cos(heading), np.sin(heading)
            half_l[b, m], half_w[b, m] = box.length_m / 2, box.width_m / 2
    return ObstacleArrays(count, x, y, hx, hy, half_l, half_w)


def no_obstacles(size: int) -> ObstacleArrays:
    """`ObstacleArrays` for `size` variants without obstacles (M = 0)."""
    return pack_obstacles([()] * size)


@njit(cache=True, inline="always")
def _slab(start, delta, half, t_lo, t_hi):  # pragma: no cover (compiled)
    """Clip the parameter interval [t_lo, t_hi] of `start + t·delta` to the slab |·| ≤ half (empty: lo > hi)."""
    if delta == 0.0:
        if abs(start) > half:
            return 1.0, 0.0
        return t_lo, t_hi
    t1 = (-half - start) / delta
    t2 = (half - start) / delta
    if t1 > t2:
        t1, t2 = t2, t1
    return max(t_lo, t1), min(t_hi, t2)


@njit(cache=True, inline="always")
def segment_hits_box(ax, ay, bx, by, cx, cy, ux, uy, half_l, half_w):  # pragma: no cover (compiled)
    """Whether the segment a→b meets the closed rectangle centred at c with unit heading u (slab test)."""
    rx, ry = ax - cx, ay - cy
    dx, dy = bx - ax, by - ay
    t_lo, t_hi = _slab(rx * ux + ry * uy, dx * ux + dy * uy, half_l, 0.0, 1.0)
    if t_lo > t_hi:
        return False
    t_lo, t_hi = _slab(ry * ux - rx * uy, dy * ux - dx * uy, half_w, t_lo, t_hi)
    return t_lo <= t_hi


@njit(cache=True, inline="always")
def _ray_clear(ax, ay, ex, ey, b, count, ox, oy, ohx, ohy, ohl, ohw):  # pragma: no cover (compiled)
    """Whether the segment apex a → end e crosses none of variant b's first `count` obstacles."""
    for m in range(count):
        if segment_hits_box(ax, ay, ex, ey, ox[b, m], oy[b, m], ohx[b, m], ohy[b, m], ohl[b, m], ohw[b, m]):
            return False
    return True


@njit(cache=True, inline="always")
def _sight_line_clear(ax, ay, ex, ey, dist, radius, c, s, b, count, ox, oy, ohx, ohy, ohl, ohw):  # pragma: no cover
    """Whether the sight line at angle θ (cos c, sin s) from the direction e to the centre reaches the circle."""
    # it first meets the circle at d·cos θ − sqrt(r² − d²·sin²θ) from the apex
    off = dist * s
    reach = dist * c - np.sqrt(max(radius * radius - off * off, 0.0))
    end_x, end_y = ax + reach * (c * ex - s * ey), ay + reach * (s * ex + c * ey)
    return _ray_clear(ax, ay, end_x, end_y, b, count, ox, oy, ohx, ohy, ohl, ohw)


@njit(cache=True, inline="always")
def footprint_visible(ax, ay, px, py, radius, b, count, ox, oy, ohx, ohy, ohl, ohw):  # pragma: no cover
    """Whether some sight line from apex a reaches the circle (p, radius) past variant b's obstacles."""
    dx, dy = px - ax, py - ay
    dist = np.sqrt(dx * dx + dy * dy)
    if dist <= radius:
        return True
    ex, ey = dx / dist, dy / dist  # towards the centre
    step = np.arcsin(radius / dist) / _PAIRS  # silhouette half-angle / rays on each side of the centre ray
    c1, s1 = np.cos(step), np.sin(step)
    c, s = 1.0, 0.0
    for i in range(_PAIRS + 1):  # angles 0, ±step, ±2·step, ... (turned by one step each round)
        if i > 0:
            c, s = c * c1 - s * s1, s * c1 + c * s1
        if _sight_line_clear(ax, ay, ex, ey, dist, radius, c, s, b, count, ox, oy, ohx, ohy, ohl, ohw):
            return True
        if i > 0 and _sight_line_clear(ax, ay, ex, ey, dist, radius, c, -s, b, count, ox, oy, ohx, ohy, ohl, ohw):
            return True
    return False


@batch_kernel
def occlude(ax, ay, px, py, radius, count, ox, oy, ohx, ohy, ohl, ohw, seen):  # pragma: no cover (compiled)
    """Clear `seen` [B, K] where no sight line from apex a [B] reaches the circle past the variant's obstacles.

    Variants without obstacles, and VRUs not seen already, are skipped.
    """
    for b in prange(px.shape[0]):
        occlude_variant(b, ax, ay, px, py, radius, count, ox, oy, ohx, ohy, ohl, ohw, seen)


@njit(cache=True, inline="always")
def occlude_variant(b, ax, ay, px, py, radius, count, ox, oy, ohx, ohy, ohl, ohw, seen):  # pragma: no cover
    """`occlude` for variant b."""
    if count[b] == 0:
        return
    for k in range(px.shape[1]):
        if seen[b, k]:
            seen[b, k] = footprint_visible(
                ax[b], ay[b], px[b, k], py[b, k], radius[b, k], b, count[b], ox, oy, ohx, ohy, ohl, ohw
            )


@njit(cache=True)
def segments_hit_box(ax, ay, bx, by, cx, cy, ux, uy, half_l, half_w):  # pragma: no cover (compiled)
    """`segment_hits_box` element-wise over 1-D arrays (for tests and tools)."""
    out = np.empty(ax.shape[0], dtype=np.bool_)
    for i in range(ax.shape[0]):
        out[i] = segment_hits_box(ax[i], ay[i], bx[i], by[i], cx[i], cy[i], ux[i], uy[i], half_l[i], half_w[i])
    return out
