"""The onboard sector sensor: distance to the filled sector, footprint perception, and the end-to-end first
detection time. References are built here with independent geometry (polar angles via atan2, explicit edge
segments, a dense polygon of the sector)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from vrusim.engine.simulate import simulate
from vrusim.scenario.loading import scenario_from_mapping
from vrusim.sim.sensing import sector
from vrusim.sim.sensing.sector import distance_to_sector, perceived

EPS = 1e-6


def _sector_args(apex, heading_rad, range_m, fov_deg):
    half = math.radians(fov_deg) / 2
    return (
        np.array([apex[0]], dtype=float),
        np.array([apex[1]], dtype=float),
        np.array([math.cos(heading_rad)]),
        np.array([math.sin(heading_rad)]),
        np.array([float(range_m)]),
        np.array([math.cos(half)]),
        np.array([math.sin(half)]),
    )


def sector_distance(apex, heading_rad, range_m, fov_deg, points):
    """distance_to_sector for one sector and a list of points → 1-D array."""
    pts = np.asarray(points, dtype=float).reshape(-1, 2)
    out = distance_to_sector(*_sector_args(apex, heading_rad, range_m, fov_deg), pts[None, :, 0], pts[None, :, 1])
    assert out.shape == (1, len(pts))
    return out[0]


def is_perceived(apex, heading_rad, range_m, fov_deg, points, radius, enabled=True):
    pts = np.asarray(points, dtype=float).reshape(-1, 2)
    out = perceived(
        *_sector_args(apex, heading_rad, range_m, fov_deg),
        pts[None, :, 0],
        pts[None, :, 1],
        np.full((1, len(pts)), float(radius)),
        np.array([enabled]),
    )
    assert out.shape == (1, len(pts))
    return out[0]


def polar(apex, heading_rad, rho, angle_rad):
    """World point at distance rho from the apex, at angle_rad from the heading (counter-clockwise)."""
    a = heading_rad + angle_rad
    return (apex[0] + rho * math.cos(a), apex[1] + rho * math.sin(a))


# ----------------------------------------------------------------------------------------------------------
# Exact edges
# ----------------------------------------------------------------------------------------------------------
FOVS = [120.0, 90.0, 200.0, 360.0]
HEADINGS = [0.0, math.radians(37.0), math.radians(-120.0), math.pi]
APEX = (3.0, -2.0)
RANGE = 20.0


@pytest.mark.parametrize("heading", HEADINGS, ids=lambda h: f"h{math.degrees(h):.0f}")
@pytest.mark.parametrize("fov", FOVS)
def test_range_arc_edge(fov, heading):
    half = math.radians(fov) / 2
    for angle in (0.0, 0.5 * half, -0.5 * half, 0.99 * half, -0.99 * half):
        inside = polar(APEX, heading, RANGE - EPS, angle)
        outside = polar(APEX, heading, RANGE + EPS, angle)
        d_in, d_out = sector_distance(APEX, heading, RANGE, fov, [inside, outside])
        assert d_in == 0.0, f"angle {angle}: just inside the arc must be inside"
        assert d_out > 0.0
        assert d_out == pytest.approx(EPS, rel=1e-3)
        # a point is a footprint of radius ~0: inside perceived, outside not
        assert list(is_perceived(APEX, heading, RANGE, fov, [inside, outside], radius=1e-9)) == [True, False]


@pytest.mark.parametrize("heading", HEADINGS, ids=lambda h: f"h{math.degrees(h):.0f}")
@pytest.mark.parametrize("fov", [f for f in FOVS if f < 360.0])
def test_angular_edges(fov, heading):
    half = math.radians(fov) / 2
    for rho in (0.5, 7.0, RANGE - 0.01):
        for side in (1.0, -1.0):
            inside = polar(APEX, heading, rho, side * (half - EPS))
            outside = polar(APEX, heading, rho, side * (half + EPS))
            d_in, d_out = sector_distance(APEX, heading, RANGE, fov, [inside, outside])
            assert d_in == 0.0
            assert d_out > 0.0
            assert d_out == pytest.approx(rho * math.sin(EPS), rel=1e-3)
            seen = is_perceived(APEX, heading, RANGE, fov, [inside, outside], radius=1e-12)
            assert list(seen) == [True, False]


@pytest.mark.parametrize("heading", HEADINGS, ids=lambda h: f"h{math.degrees(h):.0f}")
def test_full_circle_has_no_angular_edge(heading):
    # fov 360: every direction is inside, including straight behind
    pts = [polar(APEX, heading, rho, angle) for rho in (0.1, 10.0, RANGE - EPS) for angle in (math.pi, -3.0, 2.0)]
    assert np.all(sector_distance(APEX, heading, RANGE, 360.0, pts) == 0.0)
    behind_far = polar(APEX, heading, RANGE + 2.0, math.pi)
    assert sector_distance(APEX, heading, RANGE, 360.0, [behind_far])[0] == pytest.approx(2.0, abs=1e-9)


@pytest.mark.parametrize("heading", HEADINGS, ids=lambda h: f"h{math.degrees(h):.0f}")
@pytest.mark.parametrize("fov", FOVS)
def test_footprint_crossing_the_edge_is_perceived(fov, heading):
    radius = 0.5
    # beyond the range arc, on the axis
    assert is_perceived(APEX, heading, RANGE, fov, [polar(APEX, heading, RANGE + 0.49, 0.0)], radius)[0]
    assert not is_perceived(APEX, heading, RANGE, fov, [polar(APEX, heading, RANGE + 0.51, 0.0)], radius)[0]
    if fov < 360.0:
        half = math.radians(fov) / 2
        rho = 8.0
        # beside an edge ray, at perpendicular distance 0.49 / 0.51 from it (outside the angle)
        for side in (1.0, -1.0):
            for gap, expected in ((0.49, True), (0.51, False)):
                edge_point = polar(APEX, heading, rho, side * half)
                normal = heading + side * (half + math.pi / 2)  # outward normal of that edge
                centre = (edge_point[0] + gap * math.cos(normal), edge_point[1] + gap * math.sin(normal))
                assert sector_distance(APEX, heading, RANGE, fov, [centre])[0] == pytest.approx(gap, abs=1e-9)
                assert is_perceived(APEX, heading, RANGE, fov, [centre], radius)[0] == expected


def test_disabled_sensor_perceives_nothing():
    pts = [polar(APEX, 0.0, 5.0, 0.0)]
    assert is_perceived(APEX, 0.0, RANGE, 120.0, pts, 0.5, enabled=True)[0]
    assert not is_perceived(APEX, 0.0, RANGE, 120.0, pts, 0.5, enabled=False)[0]


# ----------------------------------------------------------------------------------------------------------
# Hand-computed values (fov 90°, range 10): points beside the edge rays, behind the apex, beyond the arc
# ----------------------------------------------------------------------------------------------------------
HAND_CASES = [
    # (rho, angle from heading in degrees, expected distance)
    (5.0, 60.0, 5.0 * math.sin(math.radians(15.0))),  # beside the edge: perpendicular foot on the edge
    (5.0, -60.0, 5.0 * math.sin(math.radians(15.0))),
    (2.0, 150.0, 2.0),  # more than 90° past the edge: nearest point is the apex
    (3.0, 180.0, 3.0),  # straight behind
    (2.0, 135.0, 2.0),  # exactly 90° past the edge
    (12.0, 60.0, math.sqrt(12.0**2 + 10.0**2 - 2 * 12.0 * 10.0 * math.cos(math.radians(15.0)))),  # edge end
    (15.0, 0.0, 5.0),  # beyond the arc on the axis
    (15.0, 30.0, 5.0),  # beyond the arc inside the angle
    (15.0, -45.0, 5.0),  # beyond the arc along an edge ray
    (9.0, 44.0, 0.0),
    (10.0, 46.0, 10.0 * math.sin(math.radians(1.0))),
]


@pytest.mark.parametrize("heading_deg", [0.0, 90.0, -33.0, 180.0])
@pytest.mark.parametrize(("rho", "angle_deg", "expected"), HAND_CASES)
def test_hand_computed_distances(rho, angle_deg, expected, heading_deg):
    apex = (-7.0, 11.0)
    h = math.radians(heading_deg)
    point = polar(apex, h, rho, math.radians(angle_deg))
    assert sector_distance(apex, h, 10.0, 90.0, [point])[0] == pytest.approx(expected, abs=1e-9)


@pytest.mark.parametrize("fov", FOVS)
def test_apex_itself_is_inside(fov):
    assert sector_distance(APEX, 0.3, RANGE, fov, [APEX])[0] == 0.0


def test_each_variant_uses_its_own_sector():
    """Batch of 4 sectors (different apex, heading, range, fov) x 3 points: row b only uses sector b."""
    apex = np.array([[0.0, 0.0], [10.0, -5.0], [-3.0, 7.0], [1.0, 1.0]])
    heading = np.radians([0.0, 90.0, 200.0, -45.0])
    range_m = np.array([20.0, 5.0, 12.0, 30.0])
    fov = np.array([120.0, 60.0, 250.0, 360.0])
    rng = np.random.default_rng(11)
    px = apex[:, :1] + rng.uniform(-25, 25, (4, 3))
    py = apex[:, 1:] + rng.uniform(-25, 25, (4, 3))
    half = np.radians(fov) / 2
    got = distance_to_sector(
        apex[:, 0], apex[:, 1], np.cos(heading), np.sin(heading), range_m, np.cos(half), np.sin(half), px, py
    )
    assert got.shape == (4, 3)
    for b in range(4):
        expected = reference_sector_distance(apex[b, 0], apex[b, 1], heading[b], range_m[b], fov[b], px[b], py[b])
        np.testing.assert_allclose(got[b], expected, rtol=0, atol=1e-9)
    radius = np.full((4, 3), 0.5)
    enabled = np.array([True, True, False, True])
    seen = perceived(
        apex[:, 0],
        apex[:, 1],
        np.cos(heading),
        np.sin(heading),
        range_m,
        np.cos(half),
        np.sin(half),
        px,
        py,
        radius,
        enabled,
    )
    assert np.array_equal(seen, (got <= 0.5) & enabled[:, None])


# ----------------------------------------------------------------------------------------------------------
# Property test against a dense polygon of the sector
# ----------------------------------------------------------------------------------------------------------
ARC_SEGMENTS = 4000


def sector_polygon(apex, heading, range_m, fov_deg):
    """Vertices of the sector: apex, then the arc from -half to +half (inscribed: polygon ⊂ sector)."""
    half = math.radians(fov_deg) / 2
    angles = heading + np.linspace(-half, half, ARC_SEGMENTS + 1)
    xs = np.concatenate([[apex[0]], apex[0] + range_m * np.cos(angles)])
    ys = np.concatenate([[apex[1]], apex[1] + range_m * np.sin(angles)])
    return xs, ys


def polygon_distance(xs, ys, px, py):
    """Distance from points to a filled simple polygon: 0 inside (even-odd rule), else to the nearest edge."""
    ax, ay = xs[:, None], ys[:, None]
    bx, by = np.roll(xs, -1)[:, None], np.roll(ys, -1)[:, None]
    px, py = px[None, :], py[None, :]
    abx, aby = bx - ax, by - ay
    t = np.clip(((px - ax) * abx + (py - ay) * aby) / (abx * abx + aby * aby), 0.0, 1.0)
    edge_distance = np.hypot(px - (ax + t * abx), py - (ay + t * aby)).min(axis=0)
    crosses = ((ay > py) != (by > py)) & (px < ax + (py - ay) * abx / np.where(aby == 0.0, 1.0, aby))
    inside = crosses.sum(axis=0) % 2 == 1
    return np.where(inside, 0.0, edge_distance)


RANDOM_SECTOR = {
    "apex": st.tuples(st.floats(-50, 50), st.floats(-50, 50)),
    "heading": st.floats(-math.pi, math.pi),
    "range_m": st.floats(0.5, 40.0),
    "fov": st.floats(1.0, 360.0),
    "seed": st.integers(0, 2**32 - 1),
}
"""A random sector and a seed for the points tested against it."""


@settings(max_examples=60, deadline=None)
@given(**RANDOM_SECTOR)
def test_distance_matches_dense_polygon(apex, heading, range_m, fov, seed):
    rng = np.random.default_rng(seed)
    rho = rng.uniform(0.0, 2.0 * range_m, 64)
    ang = rng.uniform(-math.pi, math.pi, 64)
    px = apex[0] + rho * np.cos(ang)
    py = apex[1] + rho * np.sin(ang)
    got = sector_distance(apex, heading, range_m, fov, np.column_stack([px, py]))
    xs, ys = sector_polygon(apex, heading, range_m, fov)
    reference = polygon_distance(xs, ys, px, py)
    # the inscribed polygon lies inside the sector: its distance is larger by at most the chord sagitta
    half = math.radians(fov) / 2
    sagitta = range_m * (1 - math.cos(half / ARC_SEGMENTS))
    tolerance = sagitta + 1e-9 * (1 + range_m)
    assert np.all(got >= 0.0)
    assert np.all(got <= reference + 1e-9 * (1 + range_m)), np.max(got - reference)
    assert np.all(reference - got <= tolerance), np.max(reference - got)


@settings(max_examples=80, deadline=None)
@given(radius=st.floats(0.0, 1.0), **RANDOM_SECTOR)
def test_the_far_screen_of_the_engine_sensor_never_changes_a_result(apex, heading, range_m, radius, fov, seed):
    """The engine's perception (`sense`) skips the exact distance of footprints clearly beyond the sector's
    circle; for footprints around that circle (within +-1e-5 relative, where a too tight screen would cut) it
    agrees with the unscreened distance <= radius."""
    rng = np.random.default_rng(seed)
    n = 256
    rho = (range_m + radius) * (1.0 + rng.uniform(-1e-5, 1e-5, n))
    rho[:16] = range_m + radius  # exactly on the reach
    ang = heading + rng.uniform(-math.radians(fov) / 2, math.radians(fov) / 2, n)  # mostly inside the opening
    px = (apex[0] + rho * np.cos(ang))[None, :]
    py = (apex[1] + rho * np.sin(ang))[None, :]
    radii = np.full((1, n), radius)
    args = _sector_args(apex, heading, range_m, fov)
    unscreened = distance_to_sector(*args, px, py) <= radii
    screened = np.empty((1, n), dtype=bool)
    sector._perceived(1, *args, np.ones(1, dtype=bool), px, py, radii, screened)
    np.testing.assert_array_equal(screened, unscreened)


def test_the_far_screen_skips_only_footprints_beyond_the_sector():
    """A footprint just inside the reach is perceived, one just beyond (past the screen's margin) is not."""
    args = _sector_args((0.0, 0.0), 0.0, 20.0, 60.0)
    px = np.array([[20.3 * (1.0 - 1e-7), 20.3 * (1.0 + 1e-5)]])
    out = np.empty((1, 2), dtype=bool)
    sector._perceived(1, *args, np.ones(1, dtype=bool), px, np.zeros((1, 2)), np.full((1, 2), 0.3), out)
    assert out.tolist() == [[True, False]]


# ----------------------------------------------------------------------------------------------------------
# End to end: first sensor detection in the paper pedestrian scenario
# ----------------------------------------------------------------------------------------------------------
def reference_sector_distance(apex_x, apex_y, heading, range_m, fov_deg, px, py):
    """Exact distance from points to a filled sector with polar angles and explicit edge segments."""
    half = math.radians(fov_deg) / 2
    dx, dy = px - apex_x, py - apex_y
    rho = np.hypot(dx, dy)
    off = (np.arctan2(dy, dx) - heading + math.pi) % (2 * math.pi) - math.pi
    in_angle = np.abs(off) <= half
    best = np.full(np.shape(px), np.inf)
    for side in (1.0, -1.0):
        ex = apex_x + range_m * np.cos(heading + side * half)
        ey = apex_y + range_m * np.sin(heading + side * half)
        sx, sy = ex - apex_x, ey - apex_y
        t = np.clip((dx * sx + dy * sy) / (range_m * range_m), 0.0, 1.0)
        best = np.minimum(best, np.hypot(dx - t * sx, dy - t * sy))
    return np.where(in_angle, np.maximum(rho - range_m, 0.0), best)


def test_first_sensor_detection_time_matches_geometry(paper_pedestrian):
    paper_pedestrian["v2x"]["enabled"] = False
    scenario = scenario_from_mapping(paper_pedestrian)
    run = simulate([scenario], trace=True)
    trace = run.trace
    ego = scenario.ego
    vru = scenario.vrus[0]
    sensor = scenario.sensor
    # positions at t = 0 (not in the trace) and at every traced time t = (i + 1) dt
    h0 = math.radians(ego.start.heading_deg)
    t = np.concatenate([[0.0], trace["t_s"]])
    centre_x = np.concatenate([[ego.start.x_m], trace["ego_x_m"][:, 0]])
    centre_y = np.concatenate([[ego.start.y_m], trace["ego_y_m"][:, 0]])
    hx = np.concatenate([[math.cos(h0)], trace["ego_heading_x"][:, 0]])
    hy = np.concatenate([[math.sin(h0)], trace["ego_heading_y"][:, 0]])
    vx = np.concatenate([[vru.start.x_m], trace["vru_x_m"][:, 0, 0]])
    vy = np.concatenate([[vru.start.y_m], trace["vru_y_m"][:, 0, 0]])
    # the apex is the centre of the front bumper, half a length ahead of the rectangle centre
    apex_x = centre_x + ego.length_m / 2 * hx
    apex_y = centre_y + ego.length_m / 2 * hy
    heading = np.arctan2(hy, hx)
    gap = np.array(
        [
            reference_sector_distance(ax, ay, h, sensor.range_m, sensor.fov_deg, x, y)
            for ax, ay, h, x, y in zip(apex_x, apex_y, heading, vx, vy, strict=True)
        ]
    )
    intersects = gap <= vru.footprint_m
    assert intersects.any(), "the pedestrian must be seen by the sensor at some point"
    first = int(np.argmax(intersects))
    assert first > 0
    assert run.metrics.first_sensor_s[0] == pytest.approx(t[first], abs=1e-9)
    # seen through its footprint: the centre itself is still outside the sector at the first detection
    assert gap[first] > 0.0
    # not a marginal case: one step earlier the footprint was clearly outside the sector
    assert gap[first - 1] > vru.footprint_m + 1e-6
