"""Occlusion of the onboard sensor by static obstacles: hand-computed sight lines, the segment–box test against
dense sampling, properties of the visibility rule, the schema, and a closed-loop CPNCO-like run checked step by
step against an independent brute-force line-of-sight reference (segment–edge intersections, 601 rays)."""

from __future__ import annotations

import copy
import math
import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from vrusim.engine.simulate import simulate
from vrusim.errors import UserInputError
from vrusim.scenario.schema import Obstacle, Pose
from vrusim.sim.sensing.occlusion import RAYS, no_obstacles, pack_obstacles, segments_hit_box
from vrusim.sim.sensing.sector import perceived

RANGE_M, FOV_DEG = 20.0, 120.0


def box(x, y, length, width, heading_deg=0.0, kind="car") -> Obstacle:
    return Obstacle(kind=kind, centre=Pose(x_m=x, y_m=y, heading_deg=heading_deg), length_m=length, width_m=width)


def seen(vru, radius, boxes, apex=(0.0, 0.0), heading_deg=0.0, range_m=RANGE_M, fov_deg=FOV_DEG) -> bool:
    """Whether one sensor (apex, heading) perceives one VRU circle among `boxes`."""
    h, half = math.radians(heading_deg), math.radians(fov_deg) / 2
    out = perceived(
        [apex[0]],
        [apex[1]],
        [math.cos(h)],
        [math.sin(h)],
        [range_m],
        [math.cos(half)],
        [math.sin(half)],
        np.array([[vru[0]]]),
        np.array([[vru[1]]]),
        np.array([[radius]]),
        np.array([True]),
        pack_obstacles([boxes]),
    )
    assert out.shape == (1, 1)
    return bool(out[0, 0])


def sampling_step_rad(distance, radius) -> float:
    """Angle between adjacent sight lines, 2·asin(r/d) / (RAYS − 1)."""
    return 2 * math.asin(radius / distance) / (RAYS - 1)


# ----------------------------------------------------------------------------------------------------------
# Hand-computed geometry: apex at the origin looking along +x; a box 1 m deep, 2 m wide, x ∈ [4.5, 5.5],
# y ∈ [−1, 1]. Its near upper corner (4.5, 1) is at atan(1/4.5) = 0.21867 rad from the axis.
# ----------------------------------------------------------------------------------------------------------
WALL = box(5.0, 0.0, 1.0, 2.0)
CORNER_RAD = math.atan2(1.0, 4.5)


def test_directly_behind_a_box_is_hidden():
    # the outermost sight lines reach y = ±0.3·(5.5/10) < 1 across the box: all blocked
    assert seen((10.0, 0.0), 0.3, [])
    assert not seen((10.0, 0.0), 0.3, [WALL])


def test_beside_a_box_is_visible():
    # lower tangent of a circle r = 0.3 at (10, 3): 0.2915 − 0.0287 = 0.2627 rad > the corner's 0.2187 rad
    low = math.atan2(3.0, 10.0) - math.asin(0.3 / math.hypot(10.0, 3.0))
    assert low > CORNER_RAD
    assert seen((10.0, 3.0), 0.3, [WALL])


@pytest.mark.parametrize("centre_y", [2.0, 1.8])
def test_partly_behind_a_box_is_visible(centre_y):
    # the centre is hidden (its angle < corner's), the upper silhouette edge peeks out past the corner
    radius, d = 0.5, math.hypot(10.0, centre_y)
    centre, half = math.atan2(centre_y, 10.0), math.asin(radius / d)
    peek = centre + half - CORNER_RAD
    assert centre < CORNER_RAD and peek > 0.0
    if centre_y == 2.0:  # peeks by more than the sampling step: always seen
        assert peek > sampling_step_rad(d, radius)
    else:  # peeks by less than one step, but the tangent (outermost) sight line is sampled: still seen
        assert peek < sampling_step_rad(d, radius)
    assert seen((10.0, centre_y), radius, [WALL])


def test_box_behind_the_vru_does_not_hide_it():
    assert seen((10.0, 0.0), 0.3, [box(15.0, 0.0, 1.0, 4.0)])


def test_box_beyond_the_sensor_range():
    far_box = box(RANGE_M + 5.0, 0.0, 2.0, 6.0)
    assert seen((10.0, 0.0), 0.3, [far_box])  # in range, in front of the box
    # beyond the range the VRU is not perceived anyway, obstacle or not
    assert not seen((RANGE_M + 1.0, 0.0), 0.3, [])
    assert not seen((RANGE_M + 1.0, 0.0), 0.3, [far_box])


def test_apex_inside_the_footprint_sees_it():
    # a box between apex and centre would block every ray, but the apex is inside the circle
    assert seen((0.3, 0.0), 0.5, [box(0.35, 0.0, 0.05, 0.05)])
    assert not seen((0.8, 0.0), 0.5, [box(0.2, 0.0, 0.05, 2.0)])


def test_two_boxes_together_hide_what_neither_hides_alone():
    upper, lower = box(5.0, 0.5, 1.0, 1.0), box(5.0, -0.5, 1.0, 1.0)
    assert seen((10.0, 0.0), 0.3, [upper]) and seen((10.0, 0.0), 0.3, [lower])
    assert not seen((10.0, 0.0), 0.3, [upper, lower])


def test_interior_window_needs_one_sampling_step():
    """A window framed by two boxes is seen when at least one sampling step wide; a narrower one between two
    sight lines is missed (the documented sampling error)."""
    radius, d = 1.0, 10.0
    step = sampling_step_rad(d, radius)
    slit_x = 5.0

    def window(centre_rad, width_rad):
        lo, hi = centre_rad - width_rad / 2, centre_rad + width_rad / 2
        return [
            box(slit_x, slit_x * math.tan(hi) + 1.0, 0.02, 2.0),
            box(slit_x, slit_x * math.tan(lo) - 1.0, 0.02, 2.0),
        ]

    # 1.2 steps wide, centred between two sight lines: contains one of them
    assert seen((d, 0.0), radius, window(step / 2, 1.2 * step))
    # 0.5 steps wide, centred between two sight lines: contains none
    assert not seen((d, 0.0), radius, window(step / 2, 0.5 * step))
    # the same narrow window on a sight line is seen
    assert seen((d, 0.0), radius, window(step, 0.5 * step))


def test_rotated_box():
    # a diamond (square of side 1.414 turned by 45°) with vertices (4, 0), (6, 0), (5, ±1): the sight line
    # y = 0.19·x passes (5, 0.95), inside it; the same square unturned spans only |y| ≤ 0.707 there
    side = math.sqrt(2.0)
    assert not seen((10.0, 1.9), 0.01, [box(5.0, 0.0, side, side, 45.0)])
    assert seen((10.0, 1.9), 0.01, [box(5.0, 0.0, side, side, 0.0)])


def test_batch_rows_use_their_own_obstacles():
    """Three variants, different obstacle counts (M = 2): each row only sees its own boxes; padding is inert."""
    apex = np.zeros(3)
    cos_half, sin_half = math.cos(math.radians(60)), math.sin(math.radians(60))
    args = (apex, apex, np.ones(3), np.zeros(3), np.full(3, RANGE_M), np.full(3, cos_half), np.full(3, sin_half))
    px, py = np.array([[10.0, 10.0]] * 3), np.array([[0.0, 3.0]] * 3)
    radius, enabled = np.full((3, 2), 0.3), np.ones(3, dtype=bool)
    obstacles = pack_obstacles([[], [WALL], [box(10.0, 6.0, 1.0, 1.0), box(5.0, 1.5, 1.0, 1.0)]])
    assert obstacles.x_m.shape == (3, 2) and list(obstacles.count) == [0, 1, 2]
    got = perceived(*args, px, py, radius, enabled, obstacles)
    assert got.tolist() == [[True, True], [False, True], [True, False]]
    assert np.array_equal(perceived(*args, px, py, radius, enabled), perceived(*args, px, py, radius, enabled, None))
    assert np.array_equal(perceived(*args, px, py, radius, enabled, no_obstacles(3)), np.ones((3, 2), dtype=bool))


# ----------------------------------------------------------------------------------------------------------
# Segment–oriented-box test against dense sampling
# ----------------------------------------------------------------------------------------------------------
def dense_hits(a, b, centre, heading_rad, half_l, half_w, spacing):
    """Whether any of the points sampled every `spacing` along a→b (both ends included) lies in the box."""
    n = max(2, math.ceil(math.dist(a, b) / spacing) + 1)
    t = np.linspace(0.0, 1.0, n)
    x, y = a[0] + t * (b[0] - a[0]) - centre[0], a[1] + t * (b[1] - a[1]) - centre[1]
    c, s = math.cos(heading_rad), math.sin(heading_rad)
    return bool(np.any((np.abs(c * x + s * y) <= half_l) & (np.abs(-s * x + c * y) <= half_w)))


coordinate = st.floats(-10.0, 10.0)
half_size = st.floats(0.05, 4.0)


@settings(max_examples=300, deadline=None)
@given(
    a=st.tuples(coordinate, coordinate),
    b=st.tuples(coordinate, coordinate),
    centre=st.tuples(coordinate, coordinate),
    heading=st.floats(-math.pi, math.pi),
    half_l=half_size,
    half_w=half_size,
)
def test_segment_box_matches_dense_sampling(a, b, centre, heading, half_l, half_w):
    eps = 1e-3
    hit = segments_hit_box(
        *(np.array([v]) for v in (a[0], a[1], b[0], b[1], centre[0], centre[1])),
        np.array([math.cos(heading)]),
        np.array([math.sin(heading)]),
        np.array([half_l]),
        np.array([half_w]),
    )[0]
    # sampled well inside the box ⇒ a hit; a hit ⇒ some sample within eps of the box (chords ≥ eps there)
    if dense_hits(a, b, centre, heading, half_l - eps, half_w - eps, eps / 2):
        assert hit
    if hit:
        assert dense_hits(a, b, centre, heading, half_l + eps, half_w + eps, eps / 2)


def test_segment_box_hand_cases():
    def hits(a, b, heading_deg=0.0):
        h = math.radians(heading_deg)
        return segments_hit_box(
            np.array([a[0]]),
            np.array([a[1]]),
            np.array([b[0]]),
            np.array([b[1]]),
            np.array([0.0]),
            np.array([0.0]),
            np.array([math.cos(h)]),
            np.array([math.sin(h)]),
            np.array([2.0]),
            np.array([1.0]),
        )[0]

    assert hits((-5.0, 0.0), (5.0, 0.0))  # straight through
    assert hits((0.0, 0.0), (0.1, 0.1))  # wholly inside
    assert not hits((-5.0, 1.01), (5.0, 1.01))  # parallel, just above
    assert hits((-5.0, 1.0), (5.0, 1.0))  # grazing the top edge: closed box
    assert not hits((-5.0, 0.0), (-2.01, 0.0))  # stops short
    assert hits((0.0, -5.0), (0.0, 5.0))  # vertical
    assert not hits((1.5, -5.0), (1.5, 5.0), 90.0)  # turned by 90°: half length now along y, |x| ≤ 1
    assert hits((0.9, -5.0), (0.9, 5.0), 90.0)
    assert not hits((3.1, 0.0), (0.0, 3.1))  # x + y = 3.1 passes outside the corner (2, 1)
    assert hits((2.9, 0.0), (0.0, 2.9))  # x + y = 2.9 cuts the corner


# ----------------------------------------------------------------------------------------------------------
# Properties of the visibility rule
# ----------------------------------------------------------------------------------------------------------
boxes_strategy = st.lists(
    st.tuples(
        st.floats(-2.0, 14.0), st.floats(-6.0, 6.0), st.floats(0.1, 5.0), st.floats(0.1, 3.0), st.floats(-180, 180)
    ),
    min_size=1,
    max_size=5,
)


@settings(max_examples=150, deadline=None)
@given(
    vru=st.tuples(st.floats(1.0, 18.0), st.floats(-8.0, 8.0)),
    radius=st.floats(0.1, 1.5),
    boxes=boxes_strategy,
    which=st.integers(0, 4),
)
def test_moving_an_obstacle_away_never_hides(vru, radius, boxes, which):
    obstacles = [box(x, y, length, width, heading) for x, y, length, width, heading in boxes]
    which %= len(obstacles)
    before = seen(vru, radius, obstacles)
    moved = list(obstacles)
    moved[which] = box(1.0e4, -3.0e4, obstacles[which].length_m, obstacles[which].width_m)
    assert seen(vru, radius, moved) >= before
    assert seen(vru, radius, []) >= before


@settings(max_examples=150, deadline=None)
@given(
    vru=st.tuples(st.floats(1.0, 18.0), st.floats(-8.0, 8.0)),
    radius=st.floats(0.1, 1.5),
    boxes=boxes_strategy,
)
def test_sampled_rule_agrees_with_brute_force(vru, radius, boxes):
    """Seen ⇒ some part truly visible; a visible run of sight lines one sampling step wide ⇒ seen."""
    assert RAYS == 7
    obstacles = [box(x, y, length, width, heading) for x, y, length, width, heading in boxes]
    if math.hypot(*vru) <= radius:
        return
    clear, _ = brute_force_clear((0.0, 0.0), vru, radius, obstacles, 601)
    got = seen(vru, radius, obstacles)
    if got:
        assert clear.any()
    # 601 rays: 100 intervals = one sampling step (RAYS = 7); only counts when the sector test passes
    if longest_run(clear) >= 101 and seen(vru, radius, []):
        assert got


def longest_run(flags: np.ndarray) -> int:
    best = current = 0
    for flag in flags:
        current = current + 1 if flag else 0
        best = max(best, current)
    return best


# ----------------------------------------------------------------------------------------------------------
# Independent brute-force line of sight: sight lines by atan2 angles, blocked when crossing a box edge or
# ending inside the box (orientation tests), no slab test
# ----------------------------------------------------------------------------------------------------------
def box_corners(obstacle: Obstacle) -> np.ndarray:
    h = math.radians(obstacle.centre.heading_deg)
    u, v = np.array([math.cos(h), math.sin(h)]), np.array([-math.sin(h), math.cos(h)])
    c = np.array([obstacle.centre.x_m, obstacle.centre.y_m])
    hl, hw = obstacle.length_m / 2, obstacle.width_m / 2
    return np.array([c - hl * u - hw * v, c + hl * u - hw * v, c + hl * u + hw * v, c - hl * u + hw * v])


def cross(ox, oy, ax, ay, bx, by):
    return (ax - ox) * (by - oy) - (ay - oy) * (bx - ox)


def segments_blocked(a, ends, corners) -> np.ndarray:
    """For segments a → ends[i]: does it touch the convex polygon `corners` (counter-clockwise)?"""
    ax, ay = a
    bx, by = ends[:, 0], ends[:, 1]
    blocked = np.ones(len(ends), dtype=bool)  # end inside: on the left of (or on) every edge
    for i in range(4):
        (px, py), (qx, qy) = corners[i], corners[(i + 1) % 4]
        blocked &= cross(px, py, qx, qy, bx, by) >= 0.0
    for i in range(4):
        (px, py), (qx, qy) = corners[i], corners[(i + 1) % 4]
        d1, d2 = cross(ax, ay, bx, by, px, py), cross(ax, ay, bx, by, qx, qy)
        d3, d4 = cross(px, py, qx, qy, ax, ay), cross(px, py, qx, qy, bx, by)
        blocked |= (d1 * d2 <= 0.0) & (d3 * d4 <= 0.0)
    return blocked


def brute_force_clear(apex, vru, radius, obstacles, rays) -> tuple[np.ndarray, np.ndarray]:
    """Per sight line across the silhouette: unobstructed?, and its end point on the circle's near side."""
    dx, dy = vru[0] - apex[0], vru[1] - apex[1]
    d = math.hypot(dx, dy)
    angles = math.atan2(dy, dx) + np.linspace(-1.0, 1.0, rays) * math.asin(radius / d)
    ux, uy = np.cos(angles), np.sin(angles)
    along = ux * dx + uy * dy
    reach = along - np.sqrt(np.maximum(radius**2 - (d * d - along * along), 0.0))
    ends = np.column_stack([apex[0] + reach * ux, apex[1] + reach * uy])
    clear = np.ones(rays, dtype=bool)
    for obstacle in obstacles:
        clear &= ~segments_blocked(apex, ends, box_corners(obstacle))
    return clear, ends


# ----------------------------------------------------------------------------------------------------------
# Schema
# ----------------------------------------------------------------------------------------------------------
def test_obstacle_defaults_and_dump(make_scenario):
    scenario = make_scenario({"obstacles": [{"centre": {"x_m": 20.0, "y_m": -4.0}, "length_m": 4.3, "width_m": 1.8}]})
    (obstacle,) = scenario.obstacles
    assert obstacle.kind == "car" and obstacle.centre.heading_deg == 0.0
    assert make_scenario().obstacles == []
    assert type(scenario).model_validate(scenario.model_dump()) == scenario


@pytest.mark.parametrize(
    ("obstacle", "message"),
    [
        ({"centre": [1.0, 1.2], "length_m": 1.0, "width_m": 1.0}, "obstacles: obstacles[1] overlaps the ego"),
        # turned by 45°: its corner reaches into the ego rectangle (x ≤ 2.25) though its centre is 3 m ahead
        ({"centre": {"x_m": 3.0, "y_m": 0.0, "heading_deg": 45}, "length_m": 1.5, "width_m": 1.5}, "obstacles[1]"),
        ({"centre": [20.0, 0.0], "length_m": 0.0, "width_m": 1.0}, "obstacles[1].length_m: Input should be greater"),
        ({"centre": [20.0, 0.0], "length_m": 1.0, "width_m": -1.0}, "obstacles[1].width_m: Input should be greater"),
        ({"centre": [20.0, 0.0], "length_m": 1.0, "width_m": 1.0, "height_m": 2}, "obstacles[1].height_m: unknown"),
        ({"centre": [20.0, 0.0], "length_m": 1.0}, "obstacles[1].width_m: Field required"),
        ({"kind": "", "centre": [20.0, 0.0], "length_m": 1.0, "width_m": 1.0}, "obstacles[1].kind"),
    ],
)
def test_bad_obstacles_are_rejected(make_scenario, obstacle, message):
    fine = {"kind": "SUV", "centre": [20.0, -4.0], "length_m": 4.4, "width_m": 1.8}
    with pytest.raises(UserInputError, match=re.escape(message)):
        make_scenario({"obstacles": [fine, obstacle]})


def test_obstacles_next_to_the_ego_are_accepted(make_scenario):
    # ego rectangle x ∈ [−2.25, 2.25], y ∈ [−0.9, 0.9]. A box 1 nm from its side; and a turned square whose
    # bounding box overlaps the ego's (x ≥ 2.193, y ≤ 2.007) but whose |x − 2.9| + |y − 1.3| ≤ 0.707 stays
    # clear of the ego's corner (2.25, 0.9), where that sum is 1.05
    beside = {"centre": [0.0, -1.4 - 1e-9], "length_m": 4.0, "width_m": 1.0}
    diamond = {"centre": {"x_m": 2.9, "y_m": 1.3, "heading_deg": 45}, "length_m": 1.0, "width_m": 1.0}
    assert len(make_scenario({"obstacles": [beside, diamond]}).obstacles) == 2
    with pytest.raises(UserInputError, match=re.escape("obstacles[0] overlaps")):
        make_scenario({"obstacles": [{**diamond, "centre": {"x_m": 2.7, "y_m": 1.1, "heading_deg": 45}}]})


def test_at_most_16_obstacles(make_scenario):
    row = [{"centre": [10.0 + 2 * i, 5.0], "length_m": 1.0, "width_m": 1.0} for i in range(17)]
    assert len(make_scenario({"obstacles": row[:16]}).obstacles) == 16
    with pytest.raises(UserInputError, match=re.escape("obstacles: List should have at most 16 items")):
        make_scenario({"obstacles": row})


# ----------------------------------------------------------------------------------------------------------
# Closed loop: CPNCO-like, a child steps out from behind two parked cars in front of the ego (20 km/h)
# ----------------------------------------------------------------------------------------------------------
EGO_Y, EGO_W, EGO_L = -1.75, 1.8, 4.5
CHILD_X, CHILD_R = 30.0, 0.149
SMALL_L, SMALL_W, SUV_L, SUV_W = 4.316, 1.79, 4.418, 1.82


def cpnco(obstacles: bool = True) -> dict:
    small_x = CHILD_X - 1.0 - SMALL_L / 2  # front bumper 1.0 m before the child's path
    suv_x = small_x - SMALL_L / 2 - 1.0 - SUV_L / 2  # 1.0 m gap behind the small car
    side = EGO_Y - (1.0 + EGO_W / 2)  # 1 m lateral clearance from the ego's side
    data = {
        "name": "cpnco-like",
        "ego": {
            "start": {"x_m": CHILD_X - 16.8 - EGO_L / 2, "y_m": EGO_Y, "heading_deg": 0.0},
            "cruise_speed_mps": 20.0 / 3.6,
            "route": {"kind": "straight", "length_m": 60.0},
            "length_m": EGO_L,
            "width_m": EGO_W,
        },
        "sensor": {"range_m": RANGE_M, "fov_deg": FOV_DEG},
        "planner": {"name": "none"},
        "vrus": [
            {
                "type": "pedestrian",
                "start": {"x_m": CHILD_X, "y_m": -5.0},
                "heading_deg": 90.0,
                "top_speed_mps": 5.0 / 3.6,
                "radius_m": CHILD_R,
                "trigger": {"at_time_s": 0.0},
            }
        ],
        "sim": {"dt_s": 0.01, "duration_s": 4.0},
    }
    if obstacles:
        data["obstacles"] = [
            {"kind": "small car", "centre": [small_x, side - SMALL_W / 2], "length_m": SMALL_L, "width_m": SMALL_W},
            {"kind": "SUV", "centre": [suv_x, side - SUV_W / 2], "length_m": SUV_L, "width_m": SUV_W},
        ]
    return data


def states(scenario, trace):
    """Apex (front-bumper centre), heading and child centre at t = 0, dt, ... (one more row than detections)."""
    ego, vru = scenario.ego, scenario.vrus[0]
    h0 = math.radians(ego.start.heading_deg)
    cx = np.concatenate([[ego.start.x_m], trace["ego_x_m"][:, 0]])
    cy = np.concatenate([[ego.start.y_m], trace["ego_y_m"][:, 0]])
    hx = np.concatenate([[math.cos(h0)], trace["ego_heading_x"][:, 0]])
    hy = np.concatenate([[math.sin(h0)], trace["ego_heading_y"][:, 0]])
    vx = np.concatenate([[vru.start.x_m], trace["vru_x_m"][:, 0, 0]])
    vy = np.concatenate([[vru.start.y_m], trace["vru_y_m"][:, 0, 0]])
    return cx + ego.length_m / 2 * hx, cy + ego.length_m / 2 * hy, np.arctan2(hy, hx), vx, vy


def in_sector(apex, heading, points, range_m, fov_deg) -> np.ndarray:
    dx, dy = points[:, 0] - apex[0], points[:, 1] - apex[1]
    off = (np.arctan2(dy, dx) - heading + math.pi) % (2 * math.pi) - math.pi
    return (np.hypot(dx, dy) <= range_m) & (np.abs(off) <= math.radians(fov_deg) / 2)


def test_cpnco_child_detected_when_it_steps_into_view(make_scenario):
    scenario = make_scenario(base=cpnco())
    run = simulate([scenario], trace=True)
    trace = run.trace
    apex_x, apex_y, heading, vx, vy = states(scenario, trace)
    detected = trace["vru_detected"][:, 0, 0]  # row i: decided from the state at t = i·dt
    t = np.arange(len(detected)) * scenario.sim.dt_s
    visible = np.zeros(len(detected), dtype=bool)
    for i in range(len(detected)):
        apex = (apex_x[i], apex_y[i])
        clear, ends = brute_force_clear(apex, (vx[i], vy[i]), CHILD_R, scenario.obstacles, 601)
        visible[i] = bool(np.any(clear & in_sector(apex, heading[i], ends, RANGE_M, FOV_DEG)))
    assert not visible[0] and visible.any()
    first_visible = int(np.argmax(visible))
    assert not np.any(detected & ~visible), "detected while hidden"
    assert detected.any()
    first_detected = int(np.argmax(detected))
    assert 0.0 <= t[first_detected] - t[first_visible] <= 0.1 + 1e-9
    assert run.metrics.first_sensor_s[0] == pytest.approx(t[first_detected], abs=1e-9)
    # not a degenerate case: hidden for a while, then seen well inside range and field of view
    assert t[first_visible] > 0.5
    assert math.hypot(vx[first_visible] - apex_x[first_visible], vy[first_visible] - apex_y[first_visible]) > 5.0

    open_view = simulate([make_scenario(base=cpnco(obstacles=False))])
    assert open_view.metrics.first_sensor_s[0] < t[first_detected] - 0.5


def test_obstacles_do_not_affect_v2x_or_collisions(make_scenario):
    base = cpnco()
    base["v2x"] = {"enabled": True, "rsu": [CHILD_X, -8.0], "comm_range_m": 60.0, "coverage_range_m": 20.0}
    with_boxes = simulate([make_scenario(base=base)], trace=True)
    without = copy.deepcopy(base)
    del without["obstacles"]
    open_view = simulate([make_scenario(base=without)], trace=True)
    # the RSU sees the child from t = 0 either way; sensing differs, motion (planner none) does not
    assert with_boxes.metrics.first_v2x_s[0] == open_view.metrics.first_v2x_s[0] == 0.0
    assert with_boxes.metrics.first_sensor_s[0] > open_view.metrics.first_sensor_s[0]
    for name in ("ego_x_m", "vru_x_m", "vru_y_m", "clearance_m"):
        assert np.array_equal(with_boxes.trace[name], open_view.trace[name])
    assert with_boxes.metrics.collided[0] == open_view.metrics.collided[0]


def test_obstacle_variant_identical_alone_and_in_threaded_batch(monkeypatch, make_scenario):
    """Same detections alone, in a batch with more obstacles / none, serial or multi-threaded."""
    from vrusim import kernels

    target = make_scenario(base=cpnco())
    others = [make_scenario(base=cpnco(obstacles=False))]
    crowded = cpnco()
    crowded["obstacles"] += [{"centre": [60.0 + 3 * i, 10.0], "length_m": 1.0, "width_m": 1.0} for i in range(6)]
    others.append(make_scenario(base=crowded))
    alone = simulate([target], trace=True).trace["vru_detected"][:, 0, 0]
    assert np.array_equal(simulate([others[1]], trace=True).trace["vru_detected"][:, 0, 0], alone)
    batch = [others[i % 2] if i % 3 else target for i in range(30)]
    for parallel_from in (kernels.PARALLEL_MIN_BATCH, 1):
        monkeypatch.setattr(kernels, "PARALLEL_MIN_BATCH", parallel_from)
        together = simulate(batch, trace=True).trace["vru_detected"][:, :, 0]
        for b in range(0, 30, 3):
            assert np.array_equal(together[: len(alone), b], alone)
