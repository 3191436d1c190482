"""Route evaluation and the conflict analysis's shortcuts are exact: `locate_point` interpolates the segment
that holds the station (the first or last one beyond the ends), the entry projection restarts from the first
projection's last evaluation (`project_from`), which stops at a fixed point of Newton's step, and the built-in
planners skip the entry projection for VRUs that do not conflict."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from vrusim.geometry.path_table import PathTable, locate_point, project_from, project_point
from vrusim.geometry.paths import Arc, Line, PathSpec
from vrusim.kernels import njit
from vrusim.planners.conflict import analyse_vru

ROUTE = PathTable([PathSpec(-30.0, 0.0, 0.0, (Line(25.0), Arc(15.0, 0.5)))])
STRAIGHT = PathTable([PathSpec(-51.35, -1.75, 0.0, (Line(400.0),))])
"""The benchmark's route (an axis-aligned line): Newton's step often leaves the station exactly where it is."""


@njit
def _both_projections(path, station, px, py, iterations):
    x, y, tx, ty, k = locate_point(path, 0, station)
    return project_point(path, 0, station, px, py, iterations), project_from(
        path, 0, station, x, y, tx, ty, k, px, py, iterations
    )


@njit
def _every_newton_step(path, station, px, py, iterations):
    """`project_point` as it was before it stopped at fixed points: every iteration evaluates the route, and the
    number of steps that left a positive station exactly where it was."""
    x, y, tx, ty, k = locate_point(path, 0, station)
    unchanged = 0
    for _ in range(iterations):
        moved = max(station + (px - x) * tx + (py - y) * ty, 0.0)
        unchanged += moved == station and moved > 0.0
        station = moved
        x, y, tx, ty, k = locate_point(path, 0, station)
    return (station, x, y, tx, ty, k), unchanged


@njit
def _analyse(path, guess, x, y, vx, vy, ax, ay, every_distance):
    return analyse_vru(path, 0, guess, 5.0, 0.5, 0.9, 0.3, 0.25, 5.0, x, y, vx, vy, ax, ay, every_distance)


def _located_in_numpy(station):
    """`locate_point`'s result written out with NumPy: segment j = floor(station / spacing) clamped to the row's
    samples, linear between its ends."""
    xs, ys, tangents, kappas, last, inv_spacing, _, _ = ROUTE.arrays
    scaled = station * inv_spacing
    j = int(min(max(np.floor(scaled), 0.0), last[0] - 1.0))
    frac = scaled - j
    return (
        xs[j] + frac * (xs[j + 1] - xs[j]),
        ys[j] + frac * (ys[j + 1] - ys[j]),
        tangents[j, 0],
        tangents[j, 1],
        kappas[j],
    )


@njit
def _located(path, station):
    return locate_point(path, 0, station)


@settings(max_examples=300, deadline=None)
@given(
    station=st.one_of(
        st.floats(-5.0, 70.0),
        st.integers(-3, 180).map(lambda i: i * 0.2),  # sample stations (spacing 0.2 m) and just below them
        st.integers(-3, 180).map(lambda i: np.nextafter(i * 0.2, -np.inf)),
    )
)
def test_locate_point_interpolates_the_segment_holding_the_station(station):
    assert _located(ROUTE.arrays, station) == _located_in_numpy(station)


coordinate = st.floats(-40.0, 40.0)
velocity = st.floats(-6.0, 6.0)


@settings(max_examples=200, deadline=None)
@given(station=st.floats(0.0, 60.0), px=coordinate, py=coordinate, iterations=st.integers(0, 3))
def test_project_from_a_located_station_is_project_point_bit_for_bit(station, px, py, iterations):
    plain, resumed = _both_projections(ROUTE.arrays, station, px, py, iterations)
    assert plain == resumed


def _bits(values) -> list[int]:
    return np.asarray(values, dtype=np.float64).view(np.int64).tolist()


@settings(max_examples=300, deadline=None)
@given(
    route=st.sampled_from([ROUTE, STRAIGHT]),
    station=st.floats(0.0, 60.0),
    px=coordinate,
    py=coordinate,
    iterations=st.integers(0, 4),
)
def test_stopping_at_a_fixed_point_is_bit_identical_to_every_newton_step(route, station, px, py, iterations):
    expected, _ = _every_newton_step(route.arrays, station, px, py, iterations)
    assert _bits(project_point(route.arrays, 0, station, px, py, iterations)) == _bits(expected)


def test_the_benchmark_route_reaches_fixed_points_often():
    """The shortcut above is taken: on the straight route, from a guess 5 cm off, the second step leaves the
    station where the first put it in most projections (58 % of these 2,000)."""
    rng = np.random.default_rng(1)
    points = np.column_stack([rng.uniform(-50.0, 30.0, 2000), rng.uniform(-5.0, 5.0, 2000)])
    guesses = points[:, 0] + 51.35 + rng.normal(0.0, 0.05, 2000)
    hits = 0
    for (px, py), guess in zip(points, guesses, strict=True):
        (station, *_), unchanged = _every_newton_step(STRAIGHT.arrays, guess, px, py, 2)
        hits += unchanged
        assert _bits([project_point(STRAIGHT.arrays, 0, guess, px, py, 2)[0]]) == _bits([station])
    assert hits > 1000


@settings(max_examples=300, deadline=None)
@given(
    guess=st.floats(0.0, 50.0),
    x=coordinate,
    y=st.floats(-8.0, 8.0),
    vx=velocity,
    vy=velocity,
    ax=st.floats(-2.0, 2.0),
    ay=st.floats(-2.0, 2.0),
)
def test_skipping_distances_of_non_conflicts_changes_nothing_else(guess, x, y, vx, vy, ax, ay):
    every = _analyse(ROUTE.arrays, guess, x, y, vx, vy, ax, ay, True)
    conflicts_only = _analyse(ROUTE.arrays, guess, x, y, vx, vy, ax, ay, False)
    station, conflict, lead, distance, along, t_in, t_out = conflicts_only
    assert (station, conflict, lead, along, t_in, t_out) == every[:3] + every[4:]
    if conflict:
        assert distance == every[3]
    else:
        assert distance == np.inf


def test_a_crossing_pedestrian_ahead_conflicts_at_its_entry_distance():
    """Ego front bumper at station 5 m; a pedestrian at station 20 m, 3 m to the right, walking left at 1.5 m/s:
    in the corridor (half 0.9 + 0.3 + 0.25 m) within the horizon, its near edge 20 - 0.3 - 5 = 14.7 m from the
    bumper (it crosses square to the route, so its entry is at its own station)."""
    station, conflict, lead, distance, along, t_in, t_out = _analyse(
        ROUTE.arrays, 20.0, -10.0, -3.0, 0.0, 1.5, 0.0, 0.0, False
    )
    assert conflict and not lead
    assert station == 20.0 and along == 0.0
    assert abs(distance - 14.7) < 1e-12
    assert abs(t_in - (3.0 - 1.45) / 1.5) < 1e-12 and abs(t_out - (3.0 + 1.45) / 1.5) < 1e-12
