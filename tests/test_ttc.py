"""Tests for vrusim.geometry.ttc.time_to_collision (exact rectangle/circle TTC under constant velocity)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from vrusim.geometry.contact import rectangle_circle_clearance
from vrusim.geometry.ttc import time_to_collision

S = math.sqrt(0.5)


def ttc1(cx, cy, hx, hy, hl, hw, evx, evy, px, py, r, vx, vy, horizon=np.inf):
    """Single rectangle / single circle call returning a python float."""
    t = time_to_collision(
        [cx],
        [cy],
        [hx],
        [hy],
        [hl],
        [hw],
        [evx],
        [evy],
        [[px]],
        [[py]],
        [[r]],
        [[vx]],
        [[vy]],
        horizon=horizon,
    )
    assert t.shape == (1, 1)
    return float(t[0, 0])


def clearance_along(scene, times):
    """Clearance at the given times with both bodies moved at constant velocity (brute force helper)."""
    cx, cy, hx, hy, hl, hw, evx, evy, px, py, r, vx, vy = scene
    n = len(times)
    c, _, _ = rectangle_circle_clearance(
        cx + evx * times,
        cy + evy * times,
        np.full(n, hx),
        np.full(n, hy),
        np.full(n, hl),
        np.full(n, hw),
        (px + vx * times)[:, None],
        (py + vy * times)[:, None],
        np.full((n, 1), r),
    )
    return c[:, 0]


# ----------------------------------------------------------------------------------------------------------
# Hand-computed cases.
# ----------------------------------------------------------------------------------------------------------
def test_following_gap_over_closing_speed():
    # Ego 15 m/s, VRU 30 m ahead (centre to centre) at 5 m/s: gap 30 - 2.3 - 0.3 = 27.4 m, closing 10 m/s.
    t = ttc1(0.0, 0.0, 1.0, 0.0, 2.3, 0.9, 15.0, 0.0, 30.0, 0.2, 0.3, 5.0, 0.0)
    assert t == pytest.approx(2.74, rel=1e-12)


def test_following_rotated_and_translated():
    # Same scene, heading 45 degrees, translated: result must not change.
    hx = hy = S
    ox, oy = 100.0, -50.0
    t = ttc1(ox, oy, hx, hy, 2.3, 0.9, 15.0 * hx, 15.0 * hy, ox + 30.0 * hx, oy + 30.0 * hy, 0.3, 5 * hx, 5 * hy)
    assert t == pytest.approx(2.74, rel=1e-9)
    # Heading 90 degrees (north), VRU walking north ahead of the car.
    t = ttc1(0.0, 0.0, 0.0, 1.0, 2.3, 0.9, 0.0, 15.0, 0.0, 30.0, 0.3, 0.0, 5.0)
    assert t == pytest.approx(2.74, rel=1e-12)


def test_perpendicular_crossing_hits_front_face():
    # Ego 10 m/s east; pedestrian 20 m ahead, 4 m to the right, walking left (north) at 2 m/s.
    # Relative motion (-10, 2): x reaches hl + r = 2.25 at t = 1.775, where y = -4 + 3.55 = -0.45 (|y| <= hw).
    t = ttc1(0.0, 0.0, 1.0, 0.0, 2.0, 1.0, 10.0, 0.0, 20.0, -4.0, 0.25, 0.0, 2.0)
    assert t == pytest.approx(1.775, rel=1e-12)


def test_perpendicular_crossing_hits_side_of_stationary_car():
    # Stationary car; pedestrian walks into its right side: (5 - hw - r) / 2 = (5 - 1 - 0.25) / 2.
    t = ttc1(0.0, 0.0, 1.0, 0.0, 2.0, 1.0, 0.0, 0.0, 1.0, -5.0, 0.25, 0.0, 2.0)
    assert t == pytest.approx(1.875, rel=1e-12)


def test_crossing_pedestrian_passes_in_front():
    # Pedestrian crosses 2 m before the car arrives: no collision.
    t = ttc1(0.0, 0.0, 1.0, 0.0, 2.0, 1.0, 10.0, 0.0, 20.0, -6.0, 0.25, 0.0, 2.0)
    assert t == math.inf


def test_already_touching_or_overlapping_is_zero():
    assert ttc1(0.0, 0.0, 1.0, 0.0, 2.0, 1.0, 10.0, 0.0, 1.0, 0.0, 0.3, 0.0, 0.0) == 0.0  # centre inside
    assert ttc1(0.0, 0.0, 1.0, 0.0, 2.0, 1.0, 0.0, 0.0, 2.5, 0.0, 0.5, 0.0, 0.0) == 0.0  # touching, at rest
    assert ttc1(0.0, 0.0, 1.0, 0.0, 2.0, 1.0, -3.0, 0.0, 2.5, 0.0, 0.5, 0.0, 0.0) == 0.0  # touching, receding
    assert ttc1(0.0, 0.0, 1.0, 0.0, 2.0, 1.0, 0.0, 0.0, 2.3, 1.4, 0.5, 1.0, 1.0) == 0.0  # corner disk, receding
    assert ttc1(0.0, 0.0, 1.0, 0.0, 2.0, 1.0, 0.0, 0.0, 2.0, 1.0, 0.0, 0.0, 0.0) == 0.0  # r = 0 on the corner


def test_diverging_and_stationary_apart_are_inf():
    assert ttc1(0.0, 0.0, 1.0, 0.0, 2.0, 1.0, 5.0, 0.0, 10.0, 0.0, 0.3, 8.0, 0.0) == math.inf
    assert ttc1(0.0, 0.0, 1.0, 0.0, 2.0, 1.0, 0.0, 0.0, 10.0, 0.0, 0.3, 0.0, 0.0) == math.inf
    assert ttc1(0.0, 0.0, 1.0, 0.0, 2.0, 1.0, 7.0, 0.0, 10.0, 0.0, 0.3, 7.0, 0.0) == math.inf  # same velocity


def test_parallel_miss_is_inf():
    # Lateral offset 3 m > hw + r = 1.3 m: passes alongside forever.
    assert ttc1(0.0, 0.0, 1.0, 0.0, 2.0, 1.0, 10.0, 0.0, 20.0, 3.0, 0.3, 0.0, 0.0) == math.inf
    # Exactly grazing the dilated side line (|y| = hw + r) counts as contact.
    t = ttc1(0.0, 0.0, 1.0, 0.0, 2.0, 1.0, 10.0, 0.0, 20.0, 1.5, 0.5, 0.0, 0.0)
    assert t == pytest.approx((20.0 - 2.0) / 10.0, rel=1e-12)


def test_corner_graze_through_disk_part():
    # Stationary car, circle r = 0.5 moving -x at 1 m/s with y = 1.3: the box part of the dilated set is
    # entered at x = 2.5 in the corner square; the true contact is with the corner disk at (2, 1):
    # dx = sqrt(0.25 - 0.09) = 0.4, so contact at x = 2.4, t = 5 - 2.4 = 2.6 s.
    t = ttc1(0.0, 0.0, 1.0, 0.0, 2.0, 1.0, 0.0, 0.0, 5.0, 1.3, 0.5, -1.0, 0.0)
    assert t == pytest.approx(2.6, rel=1e-12)
    # Same graze on the rear-right corner of a car heading north (local frame rotated by 90 degrees).
    t = ttc1(0.0, 0.0, 0.0, 1.0, 2.0, 1.0, 0.0, 0.0, 1.3, -5.0, 0.5, 0.0, 1.0)
    assert t == pytest.approx(2.6, rel=1e-12)


def test_corner_square_miss_is_inf():
    # Line x + y = 3.9 crosses the corner square [2, 2.5] x [1, 1.5] but stays 0.636 m > r from the corner.
    assert ttc1(0.0, 0.0, 1.0, 0.0, 2.0, 1.0, 0.0, 0.0, 4.4, -0.5, 0.5, -1.0, 1.0) == math.inf


def test_start_inside_corner_square_outside_disk():
    # Circle centre in the corner square [2, 2.5] x [1, 1.5] but 0.566 m > r from the corner (2, 1).
    args = (0.0, 0.0, 1.0, 0.0, 2.0, 1.0, 0.0, 0.0, 2.4, 1.4, 0.5)
    assert ttc1(*args, 1.0, 0.0) == math.inf  # receding
    assert ttc1(*args, 0.0, 0.0) == math.inf  # at rest
    # Approaching the corner along the diagonal: gap sqrt(0.32) - 0.5 at sqrt(2) m/s.
    assert ttc1(*args, -1.0, -1.0) == pytest.approx((math.sqrt(0.32) - 0.5) / math.sqrt(2.0), rel=1e-12)


def test_exactly_touching_corner_disk_without_approach_is_zero():
    # Offset (0.375, 0.5) from the corner (2, 1) has length 0.625 = r exactly (dyadic numbers).
    args = (0.0, 0.0, 1.0, 0.0, 2.0, 1.0, 0.0, 0.0, 2.375, 1.5, 0.625)
    assert ttc1(*args, 0.0, 0.0) == 0.0  # at rest
    assert ttc1(*args, 0.5, -0.375) == 0.0  # tangential
    assert ttc1(*args, 0.375, 0.5) == 0.0  # receding


def test_entry_just_inside_corner_square_uses_disk():
    # y = hw + 5e-4 with r = 0.01: contact at x = hl + sqrt(r^2 - 2.5e-7), not at the box face x = hl + r.
    t = ttc1(0.0, 0.0, 1.0, 0.0, 2.0, 1.0, 0.0, 0.0, 5.0, 1.0005, 0.01, -1.0, 0.0)
    assert t == pytest.approx(3.0 - math.sqrt(1e-4 - 2.5e-7), rel=1e-12)


def test_zero_radius_through_exact_corner():
    t = ttc1(0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0, 0.0, 5.0, 5.0, 0.0, -1.0, -1.0)
    assert t == pytest.approx(4.0, rel=1e-12)
    # Rotated by 30 degrees (inexact arithmetic): still hits the corner.
    c, s = math.cos(math.pi / 6), math.sin(math.pi / 6)
    px, py = 5 * c - 5 * s, 5 * s + 5 * c
    t = ttc1(0.0, 0.0, c, s, 1.0, 1.0, 0.0, 0.0, px, py, 0.0, -px / 5, -py / 5)
    assert t == pytest.approx(4.0, rel=1e-9)


def test_horizon():
    args = (0.0, 0.0, 1.0, 0.0, 2.3, 0.9, 15.0, 0.0, 30.0, 0.2, 0.3, 5.0, 0.0)
    assert ttc1(*args, horizon=2.0) == math.inf
    assert ttc1(*args, horizon=3.0) == pytest.approx(2.74)


def test_batch_shapes_and_scalars():
    b, k = 3, 2
    t = time_to_collision(
        np.zeros(b),
        np.zeros(b),
        np.ones(b),
        np.zeros(b),
        np.full(b, 2.0),
        np.full(b, 1.0),
        np.array([10.0, 0.0, 5.0]),
        np.zeros(b),
        np.array([[20.0, 5.0], [5.0, 0.0], [12.0, 20.0]]),
        np.zeros((b, k)),
        0.5,
        0.0,
        0.0,
    )
    assert t.shape == (b, k)
    np.testing.assert_allclose(t, [[1.75, 0.25], [math.inf, 0.0], [1.9, 3.5]])
    assert np.shape(time_to_collision(0, 0, 1, 0, 2, 1, 10, 0, 20, 0, 0.5, 0, 0)) == ()


# ----------------------------------------------------------------------------------------------------------
# Property tests.
# ----------------------------------------------------------------------------------------------------------
HORIZON = 2.0
DT = 1e-4
TIMES = np.linspace(0.0, HORIZON, round(HORIZON / DT) + 1)
# Sub-micro speeds and headings are excluded here: they make the brute-force clearance underflow (a
# 1e-200 m gap squares to 0), which says nothing about the TTC; the no-NaN test covers such input.
speed = st.one_of(st.just(0.0), st.floats(-12.0, 12.0, allow_subnormal=False).filter(lambda v: abs(v) > 1e-6))


def unit_vector(th):
    hx, hy = math.cos(th), math.sin(th)
    if abs(hx) < 1e-9 or abs(hy) < 1e-9:
        return (0.0, math.copysign(1.0, hy)) if abs(hx) < abs(hy) else (math.copysign(1.0, hx), 0.0)
    return hx, hy


@st.composite
def moving_scenes(draw):
    """Random poses; half the time aimed so that the circle would pass a point near the car at t*."""
    hx, hy = unit_vector(draw(st.floats(0.0, 2 * math.pi, allow_subnormal=False)))
    cx, cy = draw(st.floats(-10, 10, allow_subnormal=False)), draw(st.floats(-10, 10, allow_subnormal=False))
    hl, hw = draw(st.floats(0.0, 2.5, allow_subnormal=False)), draw(st.floats(0.0, 1.2, allow_subnormal=False))
    r = draw(st.one_of(st.just(0.0), st.floats(0.0, 1.0, allow_subnormal=False)))
    evx, evy, vx, vy = draw(speed), draw(speed), draw(speed), draw(speed)
    if draw(st.booleans()):
        # Target point in the car frame at time t*, in world coordinates at that time.
        t_star = draw(st.floats(0.0, HORIZON, allow_subnormal=False))
        lx = draw(st.floats(-(hl + r + 1.0), hl + r + 1.0))
        ly = draw(st.floats(-(hw + r + 1.0), hw + r + 1.0))
        tx = cx + evx * t_star + lx * hx - ly * hy
        ty = cy + evy * t_star + lx * hy + ly * hx
        px, py = tx - vx * t_star, ty - vy * t_star
    else:
        px, py = draw(st.floats(-25, 25, allow_subnormal=False)), draw(st.floats(-25, 25, allow_subnormal=False))
    return cx, cy, hx, hy, hl, hw, evx, evy, px, py, r, vx, vy


@settings(max_examples=200, deadline=None)
@given(moving_scenes())
def test_ttc_matches_brute_force_time_stepping(scene):
    t = ttc1(*scene, horizon=HORIZON)
    c = clearance_along(scene, TIMES)
    touching = np.flatnonzero(c <= 0.0)
    if touching.size:
        t_brute = TIMES[touching[0]]
        if math.isinf(t):  # only acceptable as a numerically tangential graze
            assert c.min() >= -1e-9
        else:
            assert t_brute - DT - 1e-9 <= t <= t_brute + 1e-9
            assert abs(t - t_brute) <= 2e-4
    elif not math.isinf(t):
        # The exact contact interval fell between two samples: must be a genuine (short) graze.
        assert 0.0 <= t <= HORIZON
        c_at = clearance_along(scene, np.array([t, t - DT, t + DT]))
        assert abs(c_at[0]) <= 1e-9
        assert c_at[1] > 0.0 or t < DT
        assert c_at[2] > 0.0


@settings(max_examples=100, deadline=None)
@given(moving_scenes())
def test_ttc_is_first_touch(scene):
    """At a finite positive TTC the clearance is zero, and positive just before it."""
    t = ttc1(*scene)
    assert t >= 0.0 and not math.isnan(t)
    if 0.0 < t < 1e6:
        c = clearance_along(scene, np.array([t, 0.999999 * t, 0.0]))
        scale = 1.0 + math.hypot(scene[8], scene[9]) + math.hypot(scene[0], scene[1])
        assert abs(c[0]) <= 1e-9 * scale * max(1.0, t)
        assert c[1] > -1e-9 * scale * max(1.0, t)
        assert c[2] > 0.0
    elif t == 0.0:
        assert clearance_along(scene, np.array([0.0]))[0] <= 1e-12


special = st.sampled_from([0.0, -0.0, 1.0, -1.0, 0.5, 2.0, 1.5, 2.5, -2.5, 3.0])
value = st.one_of(special, st.floats(-30.0, 30.0, allow_nan=False, allow_subnormal=False))
nonneg = st.one_of(st.sampled_from([0.0, 0.5, 1.0, 2.0]), st.floats(0.0, 3.0, allow_subnormal=False))


@settings(max_examples=60, deadline=None)
@given(st.data(), st.integers(1, 8), st.integers(1, 3))
def test_no_nan_for_random_and_degenerate_input(data, b, k):
    def arr(strategy, shape):
        n = int(np.prod(shape))
        return np.array(data.draw(st.lists(strategy, min_size=n, max_size=n)), dtype=float).reshape(shape)

    axis = data.draw(st.sampled_from([(1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (S, S), (0.6, -0.8)]))
    hx, hy = np.full(b, axis[0]), np.full(b, axis[1])
    with np.errstate(divide="raise", invalid="raise", over="raise"):  # no warnings may leak out either
        t = time_to_collision(
            arr(value, b),
            arr(value, b),
            hx,
            hy,
            arr(nonneg, b),
            arr(nonneg, b),
            arr(special, b),
            arr(special, b),
            arr(value, (b, k)),
            arr(value, (b, k)),
            arr(nonneg, (b, k)),
            arr(special, (b, k)),
            arr(special, (b, k)),
        )
    assert t.shape == (b, k)
    assert not np.isnan(t).any()
    assert (t >= 0.0).all()


@settings(max_examples=50, deadline=None)
@given(st.integers(1, 6), st.integers(1, 4), st.integers(0, 2**32 - 1))
def test_batch_equals_per_element(b, k, seed):
    rng = np.random.default_rng(seed)
    th = rng.uniform(0, 2 * np.pi, b)
    rect = [rng.normal(0, 3, b), rng.normal(0, 3, b), np.cos(th), np.sin(th), rng.uniform(0, 3, b)]
    rect += [rng.uniform(0, 1.5, b), rng.normal(0, 8, b), rng.normal(0, 2, b)]
    circ = [rng.normal(0, 10, (b, k)), rng.normal(0, 10, (b, k)), rng.uniform(0, 1, (b, k))]
    circ += [rng.normal(0, 3, (b, k)), rng.normal(0, 3, (b, k))]
    circ[3][rng.random((b, k)) < 0.3] = 0.0
    t = time_to_collision(*rect, *circ)
    assert t.shape == (b, k)
    for i in range(b):
        for j in range(k):
            assert ttc1(*(a[i] for a in rect), *(a[i, j] for a in circ)) == t[i, j]
