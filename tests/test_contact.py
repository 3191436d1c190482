"""Tests for vrusim.geometry.contact: rectangle/circle clearance, outline point, impact side and fraction."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from vrusim.geometry.contact import (
    IMPACT_SIDE_NAMES,
    impact_side,
    lateral_impact_fraction,
    rectangle_circle_clearance,
    to_local_frame,
)

FRONT, REAR, LEFT, RIGHT = 0, 1, 2, 3
S = math.sqrt(0.5)


def clearance1(cx, cy, hx, hy, hl, hw, px, py, r):
    """Single rectangle / single circle call; returns python floats (clearance, outline_x, outline_y)."""
    c, ox, oy = rectangle_circle_clearance([cx], [cy], [hx], [hy], [hl], [hw], [[px]], [[py]], [[r]])
    assert c.shape == ox.shape == oy.shape == (1, 1)
    return float(c[0, 0]), float(ox[0, 0]), float(oy[0, 0])


# ----------------------------------------------------------------------------------------------------------
# Independent reference: distance to the four edges as world-frame segments, inside test by cross products.
# ----------------------------------------------------------------------------------------------------------
def world_corners(cx, cy, hx, hy, hl, hw):
    """Corners in counter-clockwise order (front-right, front-left, rear-left, rear-right)."""
    fwd = np.array([hx, hy])
    left = np.array([-hy, hx])
    c = np.array([cx, cy])
    return [
        c + hl * fwd - hw * left,
        c + hl * fwd + hw * left,
        c - hl * fwd + hw * left,
        c - hl * fwd - hw * left,
    ]


def point_segment_distance(p, a, b):
    ab = b - a
    denom = float(ab @ ab)
    t = 0.0 if denom == 0.0 else min(max(float((p - a) @ ab) / denom, 0.0), 1.0)
    return float(np.linalg.norm(p - (a + t * ab)))


def reference_clearance(cx, cy, hx, hy, hl, hw, px, py, r):
    """Signed distance by brute geometry (no local frame, no box SDF formula)."""
    corners = world_corners(cx, cy, hx, hy, hl, hw)
    p = np.array([px, py])
    d = min(point_segment_distance(p, corners[i], corners[(i + 1) % 4]) for i in range(4))
    inside = all(
        (corners[(i + 1) % 4][0] - corners[i][0]) * (p[1] - corners[i][1])
        - (corners[(i + 1) % 4][1] - corners[i][1]) * (p[0] - corners[i][0])
        > 0.0
        for i in range(4)
    )
    return (-d if inside else d) - r, d


def local_to_world(cx, cy, hx, hy, lx, ly):
    return cx + lx * hx - ly * hy, cy + lx * hy + ly * hx


# ----------------------------------------------------------------------------------------------------------
# Hand-computed cases (rectangle hl = 2, hw = 1 unless stated).
# ----------------------------------------------------------------------------------------------------------
def test_circle_directly_ahead_of_front_edge():
    c, ox, oy = clearance1(0.0, 0.0, 1.0, 0.0, 2.0, 1.0, 5.0, 0.3, 0.5)
    assert c == pytest.approx(5.0 - 2.0 - 0.5, abs=1e-12)
    assert (ox, oy) == pytest.approx((2.0, 0.3), abs=1e-12)
    assert impact_side(ox, oy, 2.0, 1.0) == FRONT
    assert lateral_impact_fraction(oy, 1.0) == pytest.approx(0.65)


def test_circle_beside_left_edge():
    c, ox, oy = clearance1(0.0, 0.0, 1.0, 0.0, 2.0, 1.0, 0.5, 3.0, 0.4)
    assert c == pytest.approx(3.0 - 1.0 - 0.4, abs=1e-12)
    assert (ox, oy) == pytest.approx((0.5, 1.0), abs=1e-12)
    assert impact_side(ox, oy, 2.0, 1.0) == LEFT


def test_circle_beside_right_edge_and_behind():
    c, ox, oy = clearance1(0.0, 0.0, 1.0, 0.0, 2.0, 1.0, -1.0, -2.5, 0.5)
    assert c == pytest.approx(1.0, abs=1e-12)
    assert (ox, oy) == pytest.approx((-1.0, -1.0), abs=1e-12)
    assert impact_side(ox, oy, 2.0, 1.0) == RIGHT
    c, ox, oy = clearance1(0.0, 0.0, 1.0, 0.0, 2.0, 1.0, -3.0, 0.5, 0.25)
    assert c == pytest.approx(0.75, abs=1e-12)
    assert impact_side(ox, oy, 2.0, 1.0) == REAR


def test_circle_near_corner_uses_euclidean_distance():
    # Centre 3 m ahead of and 4 m left of the front-left corner (2, 1): distance 5.
    c, ox, oy = clearance1(0.0, 0.0, 1.0, 0.0, 2.0, 1.0, 5.0, 5.0, 0.5)
    assert c == pytest.approx(4.5, abs=1e-12)
    assert (ox, oy) == pytest.approx((2.0, 1.0), abs=1e-12)
    assert impact_side(ox, oy, 2.0, 1.0) == FRONT  # corners belong to front/rear
    assert lateral_impact_fraction(oy, 1.0) == pytest.approx(1.0)


def test_centre_inside_is_negative_radius_plus_depth():
    # Nearest edge is the front edge (0.5 m away).
    c, ox, oy = clearance1(0.0, 0.0, 1.0, 0.0, 2.0, 1.0, 1.5, 0.2, 0.3)
    assert c == pytest.approx(-(0.3 + 0.5), abs=1e-12)
    assert (ox, oy) == pytest.approx((2.0, 0.2), abs=1e-12)
    # Nearest edge is the left edge (0.3 m away).
    c, ox, oy = clearance1(0.0, 0.0, 1.0, 0.0, 2.0, 1.0, 0.1, 0.7, 0.2)
    assert c == pytest.approx(-(0.2 + 0.3), abs=1e-12)
    assert (ox, oy) == pytest.approx((0.1, 1.0), abs=1e-12)
    assert impact_side(ox, oy, 2.0, 1.0) == LEFT
    # Nearest edge is the rear edge, zero radius.
    c, ox, oy = clearance1(0.0, 0.0, 1.0, 0.0, 2.0, 1.0, -1.9, -0.5, 0.0)
    assert c == pytest.approx(-0.1, abs=1e-12)
    assert (ox, oy) == pytest.approx((-2.0, -0.5), abs=1e-12)
    assert impact_side(ox, oy, 2.0, 1.0) == REAR


def test_interior_tie_goes_to_front_rear_edge():
    # Centre on the interior diagonal: 0.5 m from both the front and the left edge.
    c, ox, oy = clearance1(0.0, 0.0, 1.0, 0.0, 2.0, 1.0, 1.5, 0.5, 0.25)
    assert c == pytest.approx(-0.75, abs=1e-12)
    assert (ox, oy) == (2.0, 0.5)
    assert impact_side(ox, oy, 2.0, 1.0) == FRONT


def test_centre_exactly_at_rectangle_centre_and_on_outline():
    c, ox, oy = clearance1(0.0, 0.0, 1.0, 0.0, 2.0, 1.0, 0.0, 0.0, 0.5)
    assert c == pytest.approx(-1.5, abs=1e-12)  # nearest edges are the sides, 1 m away
    assert ox == 0.0 and abs(oy) == 1.0
    for px, py in [(2.0, 0.0), (2.0, 1.0), (0.0, -1.0), (-2.0, 0.4)]:
        c, ox, oy = clearance1(0.0, 0.0, 1.0, 0.0, 2.0, 1.0, px, py, 0.0)
        assert c == 0.0
        assert (ox, oy) == (px, py)


def test_touching_is_exactly_zero_and_overlap_negative():
    c, _, _ = clearance1(0.0, 0.0, 1.0, 0.0, 2.0, 1.0, 2.5, 0.0, 0.5)
    assert c == 0.0
    c, _, _ = clearance1(0.0, 0.0, 1.0, 0.0, 2.0, 1.0, 2.4, 0.0, 0.5)
    assert c == pytest.approx(-0.1, abs=1e-12)


def test_rotated_rectangle_heading_90_degrees():
    # Heading north: local x = world y, local y (left) = world -x.
    cx, cy, hx, hy = 10.0, 20.0, 0.0, 1.0
    c, ox, oy = clearance1(cx, cy, hx, hy, 2.0, 1.0, 10.0, 25.0, 0.5)
    assert c == pytest.approx(2.5, abs=1e-12)
    assert (ox, oy) == pytest.approx((2.0, 0.0), abs=1e-12)
    c, ox, oy = clearance1(cx, cy, hx, hy, 2.0, 1.0, 7.0, 20.5, 0.25)  # west = left side
    assert c == pytest.approx(3.0 - 1.0 - 0.25, abs=1e-12)
    assert (ox, oy) == pytest.approx((0.5, 1.0), abs=1e-12)
    assert impact_side(ox, oy, 2.0, 1.0) == LEFT
    c, ox, oy = clearance1(cx, cy, hx, hy, 2.0, 1.0, 12.0, 20.0, 0.25)  # east = right side
    assert impact_side(ox, oy, 2.0, 1.0) == RIGHT
    assert lateral_impact_fraction(oy, 1.0) == 0.0


def test_rotated_rectangle_heading_45_degrees():
    hx = hy = S
    # 4 m straight ahead along the heading.
    c, ox, oy = clearance1(0.0, 0.0, hx, hy, 2.0, 1.0, 4.0 * S, 4.0 * S, 0.5)
    assert c == pytest.approx(1.5, abs=1e-12)
    assert (ox, oy) == pytest.approx((2.0, 0.0), abs=1e-12)
    # World point (0, 3): local (3S, 3S) = (2.1213, 2.1213) -> beyond the front-left corner (2, 1).
    c, ox, oy = clearance1(0.0, 0.0, hx, hy, 2.0, 1.0, 0.0, 3.0, 0.1)
    assert c == pytest.approx(math.hypot(3 * S - 2.0, 3 * S - 1.0) - 0.1, abs=1e-12)
    assert (ox, oy) == pytest.approx((2.0, 1.0), abs=1e-12)
    # World point (-1, 1): local (0, sqrt 2) -> 0.4142 m left of the left edge.
    c, ox, oy = clearance1(0.0, 0.0, hx, hy, 2.0, 1.0, -1.0, 1.0, 0.0)
    assert c == pytest.approx(math.sqrt(2.0) - 1.0, abs=1e-12)
    assert (ox, oy) == pytest.approx((0.0, 1.0), abs=1e-12)


def test_impact_side_and_lateral_fraction_conventions():
    hl, hw = np.array([2.0]), np.array([0.9])
    ox = np.array([[2.0, 2.0, 2.0, 0.3, -0.5, -2.0, -2.0]])
    oy = np.array([[0.9, 0.0, -0.9, 0.9, -0.9, 0.2, -0.9]])
    side = impact_side(ox, oy, hl, hw)
    assert side.dtype == np.int8
    assert side.tolist() == [[FRONT, FRONT, FRONT, LEFT, RIGHT, REAR, REAR]]
    names = ["front", "front", "front", "left", "right", "rear", "rear"]
    assert [IMPACT_SIDE_NAMES[s] for s in side[0]] == names
    frac = lateral_impact_fraction(oy, hw)
    np.testing.assert_allclose(frac[0, :3], [1.0, 0.5, 0.0])  # front-left corner, front centre, right edge
    assert frac.shape == (1, 7)
    # Clipping and zero width.
    assert lateral_impact_fraction(np.array([[5.0, -5.0]]), np.array([1.0])).tolist() == [[1.0, 0.0]]
    assert lateral_impact_fraction(np.array([[0.0]]), np.array([0.0])).tolist() == [[0.5]]


def test_batch_broadcasting_rectangle_b_with_circles_bk():
    cx = np.array([0.0, 100.0])
    hx = np.array([1.0, 0.0])
    hy = np.array([0.0, 1.0])
    px = np.array([[5.0, 0.0, 2.0], [100.0, 97.0, 100.0]])
    py = np.array([[0.0, 3.0, 0.0], [5.0, 0.0, 0.0]])
    c, ox, oy = rectangle_circle_clearance(cx, np.zeros(2), hx, hy, [2.0, 2.0], [1.0, 1.0], px, py, 0.5)
    assert c.shape == (2, 3)
    np.testing.assert_allclose(c, [[2.5, 1.5, -0.5], [2.5, 1.5, -1.5]], atol=1e-12)
    np.testing.assert_allclose(ox, [[2.0, 0.0, 2.0], [2.0, 0.0, 0.0]], atol=1e-12)
    np.testing.assert_allclose(oy, [[0.0, 1.0, 0.0], [0.0, 1.0, 1.0]], atol=1e-12)


def test_scalar_inputs_and_no_warnings():
    with np.errstate(all="raise"):
        c, ox, oy = rectangle_circle_clearance(0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    assert np.shape(c) == ()
    assert float(c) == 0.0 and float(ox) == 0.0 and float(oy) == 0.0


def test_to_local_frame():
    lx, ly = to_local_frame([1.0], [1.0], [0.0], [1.0], [[1.0, 2.0]], [[3.0, 1.0]])
    np.testing.assert_allclose(lx, [[2.0, 0.0]], atol=1e-15)
    np.testing.assert_allclose(ly, [[0.0, -1.0]], atol=1e-15)


# ----------------------------------------------------------------------------------------------------------
# Property tests.
# ----------------------------------------------------------------------------------------------------------
coord = st.floats(-30.0, 30.0, allow_nan=False, allow_infinity=False)
angle = st.floats(0.0, 2.0 * math.pi, allow_nan=False)
half = st.floats(0.0, 3.0, allow_nan=False)
radius = st.one_of(st.just(0.0), st.floats(0.0, 1.5, allow_nan=False))
# Circle positions: anywhere, or in the rectangle's own frame close to it (interior / edges / corners).
local_offset = st.one_of(st.floats(-4.0, 4.0, allow_nan=False), st.sampled_from([0.0, 1.0, -1.0, 0.5]))


@st.composite
def scenes(draw):
    cx, cy, th = draw(coord), draw(coord), draw(angle)
    hl, hw, r = draw(half), draw(half), draw(radius)
    hx, hy = math.cos(th), math.sin(th)
    if draw(st.booleans()):
        px, py = draw(coord), draw(coord)
    else:
        lx, ly = draw(local_offset), draw(local_offset)
        px, py = local_to_world(cx, cy, hx, hy, lx, ly)
    return cx, cy, hx, hy, hl, hw, px, py, r


@settings(max_examples=200, deadline=None)
@given(scenes())
def test_clearance_matches_segment_reference(scene):
    cx, cy, hx, hy, hl, hw, px, py, _ = scene
    c, ox, oy = clearance1(*scene)
    ref, dist = reference_clearance(*scene)
    assert c == pytest.approx(ref, abs=1e-9)
    # The outline point is on the outline, at exactly the distance of the nearest boundary point.
    assert max(abs(ox) - hl, abs(oy) - hw) == pytest.approx(0.0, abs=1e-9)
    wx, wy = local_to_world(cx, cy, hx, hy, ox, oy)
    assert math.hypot(wx - px, wy - py) == pytest.approx(dist, abs=1e-9)
    assert (c <= 0.0) == (ref <= 1e-12) or abs(ref) < 1e-9


@settings(max_examples=50, deadline=None)
@given(st.floats(0.1, 3.0), st.floats(0.1, 2.0), angle, st.floats(-6, 6), st.floats(-4, 4), st.floats(0, 1))
def test_clearance_matches_dense_sampling(hl, hw, th, px, py, r):
    """Distance to densely sampled filled rectangle (outside) / outline (inside), within grid tolerance."""
    hx, hy = math.cos(th), math.sin(th)
    c, _, _ = clearance1(1.0, -2.0, hx, hy, hl, hw, px, py, r)
    n = 81
    gx, gy = np.meshgrid(np.linspace(-hl, hl, n), np.linspace(-hw, hw, n))
    wx, wy = local_to_world(1.0, -2.0, hx, hy, gx, gy)
    d = np.hypot(wx - px, wy - py)
    on_outline = (np.abs(gx) == hl) | (np.abs(gy) == hw)
    tol = math.hypot(2 * hl, 2 * hw) / (n - 1) + 1e-12
    if d.min() < tol:  # centre inside or on the rectangle (within grid resolution): compare depth
        depth = d[on_outline].min()
        assert c == pytest.approx(-depth - r, abs=tol) or c == pytest.approx(d.min() - r, abs=tol)
    else:
        assert d.min() - tol <= c + r <= d.min() + 1e-12


@settings(max_examples=200, deadline=None)
@given(scenes(), angle, coord, coord)
def test_clearance_invariant_to_rigid_motion_of_scene(scene, phi, tx, ty):
    cx, cy, hx, hy, hl, hw, px, py, r = scene
    cp, sp = math.cos(phi), math.sin(phi)

    def move(x, y):
        return cp * x - sp * y + tx, sp * x + cp * y + ty

    mcx, mcy = move(cx, cy)
    mpx, mpy = move(px, py)
    mhx, mhy = cp * hx - sp * hy, sp * hx + cp * hy
    c0, ox0, oy0 = clearance1(*scene)
    c1, ox1, oy1 = clearance1(mcx, mcy, mhx, mhy, hl, hw, mpx, mpy, r)
    assert c1 == pytest.approx(c0, abs=1e-9)
    # The local outline point is invariant too, up to tie-breaking for centres on an interior diagonal.
    lx, ly = (float(v[0, 0]) for v in to_local_frame([cx], [cy], [hx], [hy], [[px]], [[py]]))
    if abs((abs(lx) - hl) - (abs(ly) - hw)) > 1e-6 and min(abs(lx), abs(ly)) > 1e-6:
        assert (ox1, oy1) == pytest.approx((ox0, oy0), abs=1e-9)
    assert math.hypot(ox1 - lx, oy1 - ly) == pytest.approx(math.hypot(ox0 - lx, oy0 - ly), abs=1e-9)


@settings(max_examples=50, deadline=None)
@given(st.integers(1, 6), st.integers(1, 4), st.integers(0, 2**32 - 1))
def test_batch_equals_per_element(b, k, seed):
    rng = np.random.default_rng(seed)
    th = rng.uniform(0, 2 * np.pi, b)
    rect = [rng.normal(0, 5, b), rng.normal(0, 5, b), np.cos(th), np.sin(th), rng.uniform(0, 3, b)]
    rect.append(rng.uniform(0, 1.5, b))
    px, py = rng.normal(0, 4, (b, k)), rng.normal(0, 4, (b, k))
    r = rng.uniform(0, 1, (b, k))
    r[rng.random((b, k)) < 0.3] = 0.0
    c, ox, oy = rectangle_circle_clearance(*rect, px, py, r)
    side = impact_side(ox, oy, rect[4], rect[5])
    frac = lateral_impact_fraction(oy, rect[5])
    assert c.shape == ox.shape == oy.shape == side.shape == frac.shape == (b, k)
    for i in range(b):
        for j in range(k):
            single = clearance1(*(a[i] for a in rect), px[i, j], py[i, j], r[i, j])
            assert single == (c[i, j], ox[i, j], oy[i, j])
            assert impact_side(single[1], single[2], rect[4][i], rect[5][i]) == side[i, j]
            assert lateral_impact_fraction(single[2], rect[5][i]) == frac[i, j]


@settings(max_examples=100, deadline=None)
@given(scenes())
def test_impact_side_matches_outline_edge(scene):
    _, _, _, _, hl, hw, _, _, _ = scene
    _, ox, oy = clearance1(*scene)
    side = int(impact_side(ox, oy, hl, hw))
    allowed = set()
    if abs(abs(ox) - hl) <= 1e-12:
        allowed.add(FRONT if ox >= 0 else REAR)
    if abs(abs(oy) - hw) <= 1e-12:
        allowed.add(LEFT if oy >= 0 else RIGHT)
    assert side in allowed
    if abs(ox) == hl and abs(oy) == hw:  # exact corner -> front/rear
        assert side == (FRONT if ox >= 0 else REAR)
    frac = float(lateral_impact_fraction(oy, hw))
    assert 0.0 <= frac <= 1.0
    if hw > 0:
        assert frac == pytest.approx((oy + hw) / (2 * hw))
