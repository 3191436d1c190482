"""Euro NCAP clothoid turning routes: clothoid sampling against closed-form Fresnel series and an independent
integration, heading change, curvature continuity, lengths, validation, and closed-loop tracking of the four
protocol turns. Expected values come from the protocol numbers and first principles, never from the code
under test."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from vrusim.engine.simulate import simulate
from vrusim.errors import UserInputError
from vrusim.geometry.paths import (
    SAMPLE_SPACING_M,
    Arc,
    Clothoid,
    Line,
    PathSpec,
    path_poses,
    sample_path,
)
from vrusim.ncap.protocol import TURN_PATHS
from vrusim.ncap.turn_placement import ncap_turn_route
from vrusim.scenario.loading import scenario_from_mapping
from vrusim.scenario.routes import ego_route_spec, route_spec
from vrusim.scenario.schema import Route

LENGTH, REAR_OVERHANG = 4.5, 0.9  # conftest.minimal_scenario_dict
REAR_TO_CENTRE = LENGTH / 2 - REAR_OVERHANG
PROTOCOL = {  # (side, km/h): (R1 m, R2 m, alpha deg, beta deg), Euro NCAP AEB VRU v4.5.1
    ("farside", 10): (1500.0, 9.00, 20.62, 48.75),
    ("farside", 15): (1500.0, 11.75, 20.93, 48.14),
    ("farside", 20): (1500.0, 14.75, 21.79, 46.42),
    ("nearside", 10): (1500.0, 8.00, 22.85, 44.30),
}
TURN_AT, EXIT = 10.0, 20.0


def clothoid_length(r1: float, r2: float, alpha_deg: float) -> float:
    return 2 * math.radians(alpha_deg) / (1 / r1 + 1 / r2)


def fresnel_series(s: float, a: float, terms: int = 40) -> tuple[float, float]:
    """(integral of cos(a u^2), integral of sin(a u^2)) from 0 to s, by their power series."""
    theta = a * s * s  # heading of the spiral at s; the terms are s theta^n / (n! (2n + 1)), alternating in pairs
    cos_sum = sin_sum = 0.0
    for k in range(terms):
        cos_sum += (-1) ** k * s * theta ** (2 * k) / (math.factorial(2 * k) * (4 * k + 1))
        sin_sum += (-1) ** k * s * theta ** (2 * k + 1) / (math.factorial(2 * k + 1) * (4 * k + 3))
    return cos_sum, sin_sum


def clothoid_point(x0, y0, h0, k0, k1, length, u):
    """Closed form: the point at `u` on a clothoid from (x0, y0, h0), as a piece of the spiral kappa = sigma s."""
    sigma = (k1 - k0) / length
    a, s_a = sigma / 2, k0 / sigma
    c_a, s_a_int = fresnel_series(s_a, a)
    c_u, s_u_int = fresnel_series(s_a + u, a)
    dx, dy = c_u - c_a, s_u_int - s_a_int  # in the spiral's own frame, whose heading at s_a is a s_a^2
    turn = h0 - a * s_a * s_a
    return x0 + math.cos(turn) * dx - math.sin(turn) * dy, y0 + math.sin(turn) * dx + math.cos(turn) * dy


def reference_route(x0, y0, h0, sign, r1, r2, alpha_deg, beta_deg, turn_at, exit_m, ds=1e-3):
    """Independent dense integration of the turning path (line, clothoid, arc, clothoid, line), 1 mm steps.

    Curvature is linear on each piece, so the trapezoid rule integrates the heading exactly; positions use the
    trapezoid rule on cos / sin of it. Returns stations, x, y, heading.
    """
    lc = clothoid_length(r1, r2, alpha_deg)
    la = r2 * math.radians(beta_deg)
    knots = np.cumsum([0.0, turn_at, lc, la, lc, exit_m])
    s = np.unique(np.concatenate([np.arange(0.0, knots[-1], ds), knots]))
    k1, k2 = sign / r1, sign / r2
    # exact heading: integral of the piecewise linear curvature (left limits differ only at the knots)
    heading = h0 + np.concatenate([[0.0], np.cumsum(np.diff(s) * _trapezoid_curvature(s, knots, k1, k2, lc))])
    x = x0 + np.concatenate([[0.0], np.cumsum(np.diff(s) * 0.5 * (np.cos(heading[1:]) + np.cos(heading[:-1])))])
    y = y0 + np.concatenate([[0.0], np.cumsum(np.diff(s) * 0.5 * (np.sin(heading[1:]) + np.sin(heading[:-1])))])
    return s, x, y, heading


def _trapezoid_curvature(s, knots, k1, k2, lc):
    """Mean curvature over each interval [s_i, s_i+1] (no interval straddles a knot)."""
    mid = 0.5 * (s[1:] + s[:-1])
    return np.select(
        [mid < knots[1], mid < knots[2], mid < knots[3], mid < knots[4]],
        [0.0 * mid, k1 + (k2 - k1) * (mid - knots[1]) / lc, k2 + 0.0 * mid, k2 + (k1 - k2) * (mid - knots[3]) / lc],
        0.0 * mid,
    )


def distance_to_polyline(px, py, x, y) -> np.ndarray:
    """Distance of points to a dense polyline: nearest vertex, then the two segments around it."""
    out = np.empty(len(px))
    for lo in range(0, len(px), 256):
        sl = slice(lo, lo + 256)
        d2 = (px[sl, None] - x[None, :]) ** 2 + (py[sl, None] - y[None, :]) ** 2
        j = np.argmin(d2, axis=1)
        best = np.sqrt(d2[np.arange(len(j)), j])
        for a in (np.maximum(j - 1, 0), j):
            b = np.minimum(a + 1, len(x) - 1)
            ex, ey = x[b] - x[a], y[b] - y[a]
            t = np.clip(((px[sl] - x[a]) * ex + (py[sl] - y[a]) * ey) / np.maximum(ex * ex + ey * ey, 1e-30), 0, 1)
            best = np.minimum(best, np.hypot(px[sl] - x[a] - t * ex, py[sl] - y[a] - t * ey))
        out[sl] = best
    return out


def turn_spec(side: str, kph: int, x0=0.0, y0=0.0, h0=0.0) -> PathSpec:
    route = ncap_turn_route(side, kph, TURN_AT, EXIT)
    return route_spec(route, x0, y0, h0)


# ----------------------------------------------------------------------------------------------------------
# The protocol table and the route built from it
# ----------------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("key", list(PROTOCOL))
def test_ncap_turn_route_matches_protocol(key):
    r1, r2, alpha, beta = PROTOCOL[key]
    path = TURN_PATHS[key]
    assert (path.entry_radius_m, path.radius_m, path.clothoid_angle_deg, path.arc_angle_deg) == (r1, r2, alpha, beta)
    route = ncap_turn_route(*key, TURN_AT, EXIT)
    assert route.kind == ("left" if key[0] == "farside" else "right")
    assert route.turn_at_m == TURN_AT
    assert abs(2 * alpha + beta - 90.0) < 0.02  # the protocol turns are right-angle turns
    lc = clothoid_length(r1, r2, alpha)
    assert route.clothoid_length_m == pytest.approx(lc, rel=1e-12)
    assert route.length_m == pytest.approx(TURN_AT + 2 * lc + r2 * math.radians(beta) + EXIT, rel=1e-12)
    spec = turn_spec(*key)
    assert [type(p) for p in spec.pieces] == [Line, Clothoid, Arc, Clothoid, Line]
    # path length = sum of the pieces = the route length
    assert spec.length_m == pytest.approx(route.length_m, abs=1e-9)
    assert sum(p.length_m for p in spec.pieces) == pytest.approx(TURN_AT + 2 * lc + r2 * math.radians(beta) + EXIT)


def test_unknown_ncap_turn():
    with pytest.raises(ValueError, match="no Euro NCAP turn"):
        ncap_turn_route("nearside", 20, TURN_AT, EXIT)


# ----------------------------------------------------------------------------------------------------------
# Clothoid sampling against closed forms
# ----------------------------------------------------------------------------------------------------------
def test_clothoid_from_zero_curvature_small_angle_closed_form():
    """kappa = sigma s from 0: x = s - sigma^2 s^5 / 40 + ..., y = sigma s^3 / 6 - sigma^3 s^7 / 336 + ..."""
    sigma, length = 0.01, 5.0
    spec = PathSpec(0.0, 0.0, 0.0, (Clothoid(0.0, sigma * length, length),))
    s = np.linspace(0.0, length, 11)
    x, y, heading, kappa = path_poses(spec, s)
    assert np.allclose(x, s - sigma**2 * s**5 / 40 + sigma**4 * s**9 / 3456, atol=1e-9)
    assert np.allclose(y, sigma * s**3 / 6 - sigma**3 * s**7 / 336 + sigma**5 * s**11 / 42240, atol=1e-9)
    assert np.allclose(heading, sigma * s**2 / 2, atol=1e-15)
    assert np.allclose(kappa, sigma * s, atol=1e-15)


@settings(max_examples=60, deadline=None)
@given(
    k0=st.floats(-0.2, 0.2),
    k1=st.floats(-0.2, 0.2),
    length=st.floats(0.5, 20.0),
    h0=st.floats(-math.pi, math.pi),
    x0=st.floats(-100, 100),
    y0=st.floats(-100, 100),
)
def test_clothoid_samples_match_fresnel_series(k0, k1, length, h0, x0, y0):
    # the series runs along the parent spiral kappa = sigma s from its inflection point: keep its heading there
    # moderate (a nearly circular piece would sit far out on the spiral, where the series cancels badly)
    assume(abs(k1 - k0) > 1e-6 and max(k0 * k0, k1 * k1) * length / (2 * abs(k1 - k0)) < 8.0)
    piece = Clothoid(k0, k1, length)
    spec = PathSpec(x0, y0, h0, (piece,))
    samples = sample_path(spec)
    stations = np.arange(len(samples)) * SAMPLE_SPACING_M
    for row, u in zip(samples, stations, strict=True):
        if u > length:
            break
        ex, ey = clothoid_point(x0, y0, h0, k0, k1, length, u)
        assert math.hypot(row[0] - ex, row[1] - ey) < 1e-6
        heading = h0 + k0 * u + (k1 - k0) * u * u / (2 * length)
        assert row[2] == pytest.approx(math.cos(heading), abs=1e-12)
        assert row[3] == pytest.approx(math.sin(heading), abs=1e-12)
        assert row[4] == pytest.approx(k0 + (k1 - k0) * u / length, abs=1e-12)  # exact linear curvature
    # the end pose, which the next piece starts from
    x, y, heading, _ = path_poses(spec, np.array([length]))
    ex, ey = clothoid_point(x0, y0, h0, k0, k1, length, length)
    assert math.hypot(x[0] - ex, y[0] - ey) < 1e-6
    assert heading[0] == pytest.approx(h0 + piece.angle_rad, abs=1e-12)
    assert piece.angle_rad == pytest.approx(length * (k0 + k1) / 2)


# ----------------------------------------------------------------------------------------------------------
# The whole turning path
# ----------------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("key", list(PROTOCOL))
@pytest.mark.parametrize("h0", [0.0, 2.0])
def test_sampled_turn_matches_independent_integration(key, h0):
    r1, r2, alpha, beta = PROTOCOL[key]
    sign = 1.0 if key[0] == "farside" else -1.0
    x0, y0 = 3.0, -1.75
    spec = turn_spec(*key, x0, y0, h0)
    s, x, y, heading = reference_route(x0, y0, h0, sign, r1, r2, alpha, beta, TURN_AT, EXIT)
    samples = sample_path(spec)
    stations = np.arange(len(samples)) * SAMPLE_SPACING_M
    inside = stations <= s[-1]
    ref_x, ref_y = np.interp(stations[inside], s, x), np.interp(stations[inside], s, y)
    # linear interpolation of the 1 mm reference adds at most (1 mm)^2 / (8 R2) < 2e-8 m
    assert np.hypot(samples[inside, 0] - ref_x, samples[inside, 1] - ref_y).max() < 1e-4
    ref_heading = np.interp(stations[inside], s, heading)
    sampled_heading = np.arctan2(samples[inside, 3], samples[inside, 2])
    assert np.abs(np.angle(np.exp(1j * (sampled_heading - ref_heading)))).max() < 1e-6
    # analytic poses at the piece joints: pieces chain (end of one = start of the next)
    knots = np.cumsum([p.length_m for p in spec.pieces])[:-1]
    before = path_poses(spec, knots - 1e-9)
    after = path_poses(spec, knots)
    assert np.hypot(before[0] - after[0], before[1] - after[1]).max() < 1e-8
    assert np.abs(before[2] - after[2]).max() < 1e-9
    assert np.hypot(after[0] - np.interp(knots, s, x), after[1] - np.interp(knots, s, y)).max() < 1e-4


@pytest.mark.parametrize("key", list(PROTOCOL))
def test_turn_heading_change_is_two_alpha_plus_beta(key):
    _r1, _r2, alpha, beta = PROTOCOL[key]
    sign = 1.0 if key[0] == "farside" else -1.0
    h0 = 0.4
    spec = turn_spec(*key, h0=h0)
    expected = h0 + sign * math.radians(2 * alpha + beta)
    samples = sample_path(spec)
    assert math.atan2(samples[-1, 3], samples[-1, 2]) == pytest.approx(expected, abs=1e-6)
    _, _, heading, _ = path_poses(spec, np.array([spec.length_m]))
    assert heading[0] == pytest.approx(expected, abs=1e-6)


@pytest.mark.parametrize("key", list(PROTOCOL))
def test_curvature_is_continuous_but_for_the_entry_step(key):
    r1, r2, alpha, _beta = PROTOCOL[key]
    sign = 1.0 if key[0] == "farside" else -1.0
    samples = sample_path(turn_spec(*key))
    kappa = samples[:, 4]
    sharpness = (1 / r2 - 1 / r1) / clothoid_length(r1, r2, alpha)
    assert np.abs(np.diff(kappa)).max() <= 1 / r1 + SAMPLE_SPACING_M * sharpness + 1e-12
    assert np.abs(kappa).max() == pytest.approx(1 / r2)
    assert np.all(sign * kappa >= 0.0)
    # consecutive samples are one spacing apart along the curve (chord shorter by at most h^3 kappa^2 / 24)
    chords = np.hypot(np.diff(samples[:, 0]), np.diff(samples[:, 1]))
    assert np.all(chords <= SAMPLE_SPACING_M + 1e-12)
    assert np.all(chords >= SAMPLE_SPACING_M * (1 - SAMPLE_SPACING_M**2 / (24 * r2**2)) - 1e-12)


def test_plain_arc_route_is_unchanged():
    """clothoid_angle_deg 0 (the default): line, arc, line exactly as before the clothoids."""
    route = Route(kind="right", turn_at_m=5.0, radius_m=12.0, angle_deg=75.0, length_m=60.0)
    spec = route_spec(route, 1.0, 2.0, 0.3)
    arc = Arc(12.0, -math.radians(75.0))
    assert spec.pieces == (Line(5.0), arc, Line(60.0 - 5.0 - arc.length_m))


# ----------------------------------------------------------------------------------------------------------
# Validation
# ----------------------------------------------------------------------------------------------------------
def _route_error(route: dict) -> str:
    data = {
        "name": "t",
        "ego": {"start": [0, 0], "cruise_speed_mps": 5.0, "route": route},
        "vrus": [{"type": "pedestrian", "start": [500, 50], "heading_deg": 90}],
    }
    with pytest.raises(UserInputError) as info:
        scenario_from_mapping(data, "case.yaml")
    return str(info.value)


@pytest.mark.parametrize(
    ("route", "reason"),
    [
        (
            {"kind": "left", "radius_m": 9, "clothoid_angle_deg": 20, "clothoid_entry_radius_m": 9},
            "ego.route: clothoid_entry_radius_m must be larger than radius_m",
        ),
        (
            {"kind": "left", "radius_m": 9, "angle_deg": 150, "clothoid_angle_deg": 20},
            "ego.route: the turn 2 clothoid_angle_deg + angle_deg (190 deg) must be at most 180 deg",
        ),
        (
            {"kind": "right", "radius_m": 9, "angle_deg": 48.75, "clothoid_angle_deg": 20.62, "length_m": 20},
            "ego.route: length_m must cover turn_at_m + the clothoids and the arc (20.54 m)",
        ),
        ({"kind": "left", "clothoid_angle_deg": -1}, "ego.route.clothoid_angle_deg: Input should be greater than"),
        ({"kind": "left", "clothoid_angle_deg": 90}, "ego.route.clothoid_angle_deg: Input should be less than 90"),
        ({"kind": "left", "clothoid_entry_radius_m": 0}, "ego.route.clothoid_entry_radius_m: Input should be greater"),
        ({"kind": "straight", "start_in_turn_m": 1.0}, "ego.route: start_in_turn_m needs a turn"),
        ({"kind": "left", "turn_at_m": 5.0, "start_in_turn_m": 1.0}, "has no approach (turn_at_m 0)"),
        ({"kind": "left", "radius_m": 9, "angle_deg": 90, "start_in_turn_m": 20}, "shorter than the turn (14.14 m)"),
        ({"kind": "left", "start_in_turn_m": -1}, "ego.route.start_in_turn_m: Input should be greater than or equal"),
    ],
)
def test_bad_clothoid_route_is_named(route, reason):
    message = _route_error(route)
    assert reason in message, message
    assert len(message.splitlines()) == 2, message


def test_clothoid_arc_radius_must_be_reachable():
    message = _route_error({"kind": "left", "radius_m": 3.0, "angle_deg": 40, "clothoid_angle_deg": 20})
    assert "ego: route.radius_m 3.0 m is tighter than the ego can turn" in message


def test_length_check_covers_clothoids():
    lc = clothoid_length(1500.0, 9.0, 20.62)
    needed = 5.0 + 2 * lc + 9.0 * math.radians(48.75)
    base = {"kind": "left", "turn_at_m": 5.0, "radius_m": 9.0, "angle_deg": 48.75, "clothoid_angle_deg": 20.62}
    Route(**base, length_m=needed + 1e-9)
    with pytest.raises(ValueError, match="length_m must cover"):
        Route(**base, length_m=needed - 1e-6)


@settings(max_examples=40, deadline=None)
@given(
    key=st.sampled_from(sorted(PROTOCOL)),
    fraction=st.floats(0.0, 0.99),
    x0=st.floats(-50, 50),
    h0=st.floats(-math.pi, math.pi),
)
def test_a_route_that_begins_inside_its_turn_is_the_rest_of_the_whole_turn(key, fraction, x0, h0):
    """`start_in_turn_m` = s: from the whole route's pose at station s, the route's poses at u equal the whole
    route's at s + u (a rigid continuation: same heading and curvature, positions within 1e-6 m)."""
    whole = ncap_turn_route(*key, 0.0, EXIT)
    skip = fraction * whole.turn_length_m
    x, y, heading, _ = path_poses(route_spec(whole, x0, 1.0, h0), np.array([skip]))
    rest = whole.model_copy(update={"start_in_turn_m": skip, "length_m": whole.length_m - skip})
    assert rest.turn_length_m == pytest.approx(whole.turn_length_m - skip)
    stations = np.linspace(0.0, rest.length_m, 57)
    expected = path_poses(route_spec(whole, x0, 1.0, h0), stations + skip)
    got = path_poses(route_spec(rest, float(x[0]), float(y[0]), float(heading[0])), stations)
    for a, b in zip(got, expected, strict=True):
        np.testing.assert_allclose(a, b, atol=1e-6)


# ----------------------------------------------------------------------------------------------------------
# Closed-loop tracking of the protocol turns
# ----------------------------------------------------------------------------------------------------------
TRACK_CASES = [(side, kph, speed) for side, kph in PROTOCOL for speed in (10, 15, 20)]
START = (-20.0, -1.75, 15.0)  # rectangle centre (m) and heading (deg)


@pytest.fixture(scope="module")
def tracking_batch(make_scenario):
    scenarios = []
    for side, kph, speed in TRACK_CASES:
        route = ncap_turn_route(side, kph, TURN_AT, EXIT)
        scenarios.append(
            make_scenario(
                {
                    "name": f"{side}-{kph}-at-{speed}",
                    "ego": {
                        "start": {"x_m": START[0], "y_m": START[1], "heading_deg": START[2]},
                        "cruise_speed_mps": speed / 3.6,
                        "route": route.model_dump(),
                    },
                    "sim": {"duration_s": route.length_m / (speed / 3.6) + 1.0},
                }
            )
        )
    return scenarios, simulate(scenarios, trace=True)


@pytest.mark.parametrize("index", range(len(TRACK_CASES)), ids=[f"{s}{k}-{v}kph" for s, k, v in TRACK_CASES])
def test_protocol_turn_tracking_error_below_10_cm(tracking_batch, index):
    scenarios, run = tracking_batch
    side, kph, _speed = TRACK_CASES[index]
    r1, r2, alpha, beta = PROTOCOL[side, kph]
    sign = 1.0 if side == "farside" else -1.0
    assert not np.isnan(run.metrics.travel_time_s[index]), "the ego must complete its route"
    steps = int(np.argmax(run.trace["t_s"] >= run.metrics.end_time_s[index] - 1e-9)) + 1
    hx = run.trace["ego_heading_x"][:steps, index]
    hy = run.trace["ego_heading_y"][:steps, index]
    rear_x = run.trace["ego_x_m"][:steps, index] - REAR_TO_CENTRE * hx
    rear_y = run.trace["ego_y_m"][:steps, index] - REAR_TO_CENTRE * hy
    h0 = math.radians(START[2])
    x0, y0 = START[0] - REAR_TO_CENTRE * math.cos(h0), START[1] - REAR_TO_CENTRE * math.sin(h0)
    # reference with 5 m of extra exit: the last step may overshoot the route end
    _, ref_x, ref_y, _ = reference_route(x0, y0, h0, sign, r1, r2, alpha, beta, TURN_AT, EXIT + 5.0, ds=0.01)
    error = distance_to_polyline(rear_x, rear_y, ref_x, ref_y)
    assert error.max() < 0.1
    # the same route as the simulation's own table, and the turn really happened
    assert ego_route_spec(scenarios[index].ego).x0_m == pytest.approx(x0)
    final = math.atan2(hy[-1], hx[-1])
    assert math.degrees(final - (h0 + sign * math.radians(2 * alpha + beta))) == pytest.approx(0.0, abs=0.5)
