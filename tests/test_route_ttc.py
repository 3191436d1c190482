"""`planners.route_ttc` skips samples that cannot touch: its TTC is bit-identical to evaluating every sample (the
reference below is the route TTC before the skip, compiled the same way), on straight, turning and polyline routes,
for every kind of VRU motion, including contacts right after a skipped stretch."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from vrusim.geometry.contact import clearance_local, to_local
from vrusim.geometry.path_table import PathTable, locate_point
from vrusim.geometry.paths import Arc, Clothoid, Line, PathSpec, PolylineSpec
from vrusim.kernels import njit
from vrusim.planners.route_ttc import TTC_STEP_S, route_ttc


@njit
def every_sample_ttc(
    route, offset, rear_station, speed, rear_to_centre, half_length, half_width, x, y, vx, vy, decel, radius, horizon
):  # pragma: no cover (compiled)
    """The route TTC evaluated at every sample (no skipping)."""
    vru_speed = math.sqrt(vx * vx + vy * vy)
    braking = decel > 0.0 and vru_speed > 0.0
    stop_s = vru_speed / decel if braking else np.inf
    ex, ey, tx, ty, _ = locate_point(route, offset, rear_station)
    reach = (speed + vru_speed) * horizon + rear_to_centre + half_length + half_width + radius
    if math.hypot(x - ex, y - ey) > reach:
        return np.inf
    count = math.ceil(horizon / TTC_STEP_S - 1e-9)
    previous = np.inf
    for j in range(count + 1):
        t = j * TTC_STEP_S
        if j > 0:
            ex, ey, tx, ty, _ = locate_point(route, offset, rear_station + speed * t)
        cx, cy = ex + rear_to_centre * tx, ey + rear_to_centre * ty
        moving = min(t, stop_s)
        travel = moving * (1.0 - 0.5 * decel * moving / vru_speed) if braking else t
        lx, ly = to_local(cx, cy, tx, ty, x + vx * travel, y + vy * travel)
        clearance = clearance_local(lx, ly, half_length, half_width, radius)[0]
        if clearance <= 0.0:
            if j == 0:
                return 0.0
            contact = t - TTC_STEP_S + TTC_STEP_S * previous / (previous - clearance)
            return contact if contact <= horizon else np.inf
        previous = clearance
    return np.inf


ROUTES = PathTable(
    [
        PathSpec(0.0, 0.0, 0.0, (Line(300.0),)),
        PathSpec(0.0, 0.0, 0.0, (Line(15.0), Clothoid(8.0, 0.0, 1 / 9.0), Arc(9.0, math.pi / 3), Line(40.0))),
        PathSpec(0.0, 0.0, 0.3, (Line(10.0), Arc(6.0, -math.pi / 2), Line(30.0))),
        PolylineSpec(((0.0, 0.0), (20.0, 0.0), (20.0, 15.0), (45.0, 30.0))),
    ]
)


@settings(max_examples=600, deadline=None)
@given(
    row=st.integers(0, 3),
    station=st.floats(0.0, 30.0),
    speed=st.floats(0.0, 30.0),
    rel_x=st.floats(-10.0, 60.0),
    rel_y=st.floats(-20.0, 20.0),
    vru_speed=st.floats(0.0, 12.0),
    vru_heading=st.floats(-math.pi, math.pi),
    decel=st.sampled_from([0.0, 0.0, 2.0, 6.0]),
    radius=st.floats(0.1, 1.2),
    horizon=st.sampled_from([0.9, 1.6, 3.1, 4.0]),
    geometry=st.sampled_from([(0.9, 2.25, 0.9), (1.35, 2.45, 1.0), (-0.5, 2.0, 0.85)]),
)
def test_skipping_samples_gives_the_every_sample_ttc_bit_for_bit(
    row, station, speed, rel_x, rel_y, vru_speed, vru_heading, decel, radius, horizon, geometry
):
    rear_to_centre, half_length, half_width = geometry
    arrays, offset = ROUTES.arrays, row * ROUTES.width
    ex, ey, tx, ty, _ = locate_point(arrays, offset, station)
    x, y = ex + rel_x * tx - rel_y * ty, ey + rel_x * ty + rel_y * tx  # placed in the route frame at `station`
    vx, vy = vru_speed * math.cos(vru_heading), vru_speed * math.sin(vru_heading)
    args = (
        arrays,
        offset,
        station,
        speed,
        rear_to_centre,
        half_length,
        half_width,
        x,
        y,
        vx,
        vy,
        decel,
        radius,
        horizon,
    )
    expected = every_sample_ttc(*args)
    got = route_ttc(*args)
    assert np.float64(got).tobytes() == np.float64(expected).tobytes(), (got, expected)


def test_a_contact_after_a_long_skip_interpolates_from_the_sample_before_it():
    """A stationary target 40 m ahead at 20 m/s: the first ~35 samples are skipped, the contact (about 1.84 s)
    still equals the every-sample TTC, which interpolates between the two samples around it."""
    arrays = ROUTES.arrays
    args = (arrays, 0, 0.0, 20.0, 0.9, 2.25, 0.9, 40.0, 0.0, 0.0, 0.0, 0.0, 0.3, 4.0)
    expected = every_sample_ttc(*args)
    assert 1.8 < expected < 1.9
    assert route_ttc(*args) == expected


def test_the_largest_turn_of_a_route_is_its_curvature_times_the_spacing():
    """PathTable's per-row bound on the heading change between consecutive segments: 0 on a straight route, the
    arc's chord angle (spacing / radius) on a circular one, the corner on a polyline (cut over one spacing)."""
    table = PathTable(
        [
            PathSpec(0.0, 0.0, 0.4, (Line(50.0),)),
            PathSpec(0.0, 0.0, 0.0, (Arc(9.0, math.pi / 2),)),
            PolylineSpec(((0.0, 0.0), (10.0, 0.0), (10.0, 10.0))),
        ]
    )
    turns = table.arrays[7][:: table.width]
    assert turns[0] < 1e-12
    assert turns[1] == pytest.approx(table.spacing_m / 9.0, rel=1e-6)
    assert math.pi / 4 - 1e-9 <= turns[2] <= math.pi / 2 + 1e-9


TIGHT_TURN = PathTable([PathSpec(0.0, 0.0, 0.0, (Line(2.0), Arc(6.0, math.pi), Line(20.0)))])


@pytest.mark.parametrize("angle_deg", np.arange(10.0, 120.0, 2.5))
@pytest.mark.parametrize("speed", [4.0, 10.0])
def test_a_target_met_by_the_outer_front_corner_of_a_tight_turn(angle_deg, speed):
    """On a 6 m arc the outer front corner moves ~1.26 × faster than the rear axle: a stationary target on its
    sweep is met sooner than the rear axle's speed alone would allow, and the skip must allow for the turn."""
    rear_to_centre, half_length, half_width, radius = 0.9, 2.25, 0.9, 0.4  # wider than a sample of sweep
    corner_radius = math.hypot(6.0 + half_width, rear_to_centre + half_length)  # about the arc's centre (2, 6)
    phase = math.atan2(rear_to_centre + half_length, 6.0 + half_width)
    angle = math.radians(angle_deg) + phase
    x, y = 2.0 + corner_radius * math.sin(angle), 6.0 - corner_radius * math.cos(angle)
    args = (TIGHT_TURN.arrays, 0, 0.0, speed, rear_to_centre, half_length, half_width, x, y, 0.0, 0.0, 0.0, radius, 4.0)
    expected = every_sample_ttc(*args)
    assert expected < np.inf
    assert route_ttc(*args) == expected
