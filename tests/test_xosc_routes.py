"""Routes, trajectory shapes, trajectory timing and relative positions (issue 19): hand-written files in
tests/data/xosc/routes/ (a junction whose left turn is an arc: lane -1's centre is the circle of radius 12 m about
(0, 10.25)) imported, run with planner `none` and checked against analytic motion (<= 0.01 s, <= 0.02 m);
constructs vrusim cannot represent exactly are refused (exit 2) naming the element and its line."""

from __future__ import annotations

import math
import shutil
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import quad
from scipy.special import fresnel

from vrusim.engine.simulate import simulate
from vrusim.formats.xml_file import parse_xml
from vrusim.formats.xodr_reader import read_xodr
from vrusim.formats.xosc_clothoid import clothoid_poses
from vrusim.formats.xosc_document import XoscDocument
from vrusim.formats.xosc_import import read_xosc
from vrusim.formats.xosc_model import WorldPose
from vrusim.formats.xosc_relative_positions import relative_lane_id
from vrusim.formats.xosc_route_action import route_shape
from vrusim.sources import apply_planner_and_seed
from xosc_helpers import edited, refused_at

DATA = Path(__file__).parent / "data" / "xosc" / "routes"
TIME_TOL_S, DISTANCE_TOL_M = 0.01, 0.02
CENTRE = (0.0, 10.25)
"""Centre of the left turn's arc; lane -1 of connecting road 100 runs on the circle of radius 12 m about it."""
RADIUS_M = 12.0


def _trace(path: Path) -> dict[str, np.ndarray]:
    scenario = apply_planner_and_seed(read_xosc(path), "none")
    return simulate([scenario], trace=True).trace


def _at(trace: dict[str, np.ndarray], key: str, t_s: float, column: int = 0) -> float:
    values = trace[key].reshape(len(trace["t_s"]), -1)[:, column]
    return float(np.interp(t_s, trace["t_s"], values))


def _vru_xy(trace: dict[str, np.ndarray], t_s: float) -> tuple[float, float]:
    return _at(trace, "vru_x_m", t_s), _at(trace, "vru_y_m", t_s)


def _on_turn(angle_rad: float) -> tuple[float, float]:
    """The point `angle_rad` into the left turn on lane -1's centre circle."""
    return CENTRE[0] + RADIUS_M * math.sin(angle_rad), CENTRE[1] - RADIUS_M * math.cos(angle_rad)


def _copy(tmp_path: Path, name: str) -> Path:
    shutil.copy(DATA / "junction.xodr", tmp_path / "junction.xodr")
    shutil.copytree(DATA / "catalogs", tmp_path / "catalogs")
    shutil.copy(DATA / name, tmp_path / name)
    return tmp_path / name


def _edited(tmp_path: Path, name: str, old: str, new: str) -> Path:
    """A copy of `name` with the first `old` replaced (the last one when `old` starts with "LAST:")."""
    return edited(_copy(tmp_path, name), old.removeprefix("LAST:"), new, last=old.startswith("LAST:"))


# --------------------------------------------------------------------------------------------- routes


def _route(waypoints: str) -> list[WorldPose]:
    network = read_xodr(DATA / "junction.xodr")
    element = parse_xml(f'<Route name="r" closed="false">{waypoints}</Route>', "route.xosc")
    return route_shape(XoscDocument("route.xosc"), element, network, {}).vertices


def _lane_waypoint(road: str, lane: int, s: float, strategy: str = "shortest") -> str:
    position = f'<LanePosition roadId="{road}" laneId="{lane}" s="{s}"/>'
    return f'<Waypoint routeStrategy="{strategy}"><Position>{position}</Position></Waypoint>'


def test_a_route_through_the_junction_follows_the_connecting_roads_arc():
    vertices = _route(_lane_waypoint("1", -1, 10.0) + _lane_waypoint("2", -1, 30.0))
    xy = np.array([(v.x_m, v.y_m) for v in vertices[:-1]])  # without the run-out
    heading = np.array([v.heading_rad for v in vertices[:-1]])
    approach, turn, exit_ = xy[:, 0] <= 0.0, (xy[:, 0] > 0.0) & (xy[:, 1] < CENTRE[1]), xy[:, 1] >= CENTRE[1]
    assert approach.sum() + turn.sum() + exit_.sum() == len(xy)
    np.testing.assert_allclose(xy[approach, 1], -1.75, atol=1e-12)
    np.testing.assert_allclose(heading[approach], 0.0, atol=1e-9)
    radius = np.hypot(xy[turn, 0] - CENTRE[0], xy[turn, 1] - CENTRE[1])
    np.testing.assert_allclose(radius, RADIUS_M, atol=1e-9)
    angle = np.arctan2(xy[turn, 0] - CENTRE[0], CENTRE[1] - xy[turn, 1])
    np.testing.assert_allclose(heading[turn], angle, atol=1e-8)  # the tangent of the circle
    np.testing.assert_allclose(xy[exit_, 0], 12.0, atol=1e-12)
    np.testing.assert_allclose(xy[[0, -1]], [[-40.0, -1.75], [12.0, 40.25]], atol=1e-12)
    assert np.all(np.hypot(*np.diff(xy, axis=0).T) <= 0.2 * RADIUS_M / 10.25 + 1e-9)  # 0.2 m along s
    end = vertices[-1]  # the straight run-out
    assert (end.x_m, end.y_m) == pytest.approx((12.0, 50.25), abs=1e-9)


def test_the_shortest_route_to_road_3_goes_straight_through_the_junction():
    vertices = _route(_lane_waypoint("1", -1, 45.0) + _lane_waypoint("3", -1, 5.0, "leastIntersections"))
    xy = np.array([(v.x_m, v.y_m) for v in vertices[:-1]])
    np.testing.assert_allclose(xy[:, 1], -1.75, atol=1e-12)
    assert xy[0, 0] == pytest.approx(-5.0) and xy[-1, 0] == pytest.approx(25.5)


def test_two_waypoints_on_one_lane_are_joined_along_it():
    vertices = _route(_lane_waypoint("2", -1, 5.0) + _lane_waypoint("2", -1, 25.0))
    ends = [vertices[0].x_m, vertices[0].y_m, vertices[-2].x_m, vertices[-2].y_m]
    assert ends == pytest.approx([12.0, 15.25, 12.0, 35.25])


def test_an_ego_route_becomes_line_turn_line_and_is_driven():
    scenario = read_xosc(DATA / "ego_route_junction.xosc")
    route = scenario.ego.route
    assert route.kind == "left"
    assert route.turn_at_m == pytest.approx(40.0, abs=1e-6)
    assert route.radius_m == pytest.approx(RADIUS_M, abs=1e-6)
    assert route.angle_deg == pytest.approx(90.0, abs=1e-6)
    assert route.length_m == pytest.approx(40.0 + RADIUS_M * math.pi / 2 + 30.0, abs=1e-6)
    assert (scenario.ego.start.x_m, scenario.ego.start.y_m) == pytest.approx((-40.0 + 1.35, -1.75))
    catalog = read_xosc(DATA / "ego_route_catalog.xosc").ego.route
    assert catalog.model_dump() == pytest.approx(route.model_dump())
    trace = _trace(DATA / "ego_route_junction.xosc")
    assert _at(trace, "ego_station_m", 5.0) == pytest.approx(50.0, abs=DISTANCE_TOL_M)


def test_a_vru_route_is_its_path_through_the_junction():
    trace = _trace(DATA / "vru_route_junction.xosc")
    assert _vru_xy(trace, 2.0) == pytest.approx((-10.0, -1.75), abs=DISTANCE_TOL_M)
    assert _vru_xy(trace, 5.0) == pytest.approx(_on_turn(5.0 / RADIUS_M), abs=DISTANCE_TOL_M)  # 5 m into the arc
    on_road_2 = 45.0 - (20.0 + RADIUS_M * math.pi / 2)
    assert _vru_xy(trace, 9.0) == pytest.approx((12.0, CENTRE[1] + on_road_2), abs=DISTANCE_TOL_M)
    assert _vru_xy(trace, 11.0) == pytest.approx((12.0, CENTRE[1] + on_road_2 + 10.0), abs=DISTANCE_TOL_M)  # on past it


# --------------------------------------------------------------------------------------------- clothoids


def _fresnel_end(x0: float, y0: float, h0: float, sharpness: float, length: float) -> tuple[float, float, float]:
    """End pose of a clothoid from curvature 0 (Fresnel integrals)."""
    scale = math.sqrt(math.pi / sharpness)
    s_int, c_int = fresnel(length / scale)
    u, v = scale * c_int, scale * s_int
    return (
        x0 + u * math.cos(h0) - v * math.sin(h0),
        y0 + u * math.sin(h0) + v * math.cos(h0),
        h0 + sharpness * length**2 / 2,
    )


def test_a_clothoid_ends_at_the_fresnel_end_pose_and_the_vru_gets_there():
    scenario = read_xosc(DATA / "vru_clothoid.xosc")
    x, y, h = _fresnel_end(0.0, -6.0, math.pi / 2, 0.02, 10.0)
    end = scenario.vrus[0].path[-2]  # the last is the run-out
    assert (end.x_m, end.y_m) == pytest.approx((x, y), abs=1e-9)
    run_out = scenario.vrus[0].path[-1]
    assert math.atan2(run_out.y_m - end.y_m, run_out.x_m - end.x_m) == pytest.approx(h, abs=1e-9)
    trace = _trace(DATA / "vru_clothoid.xosc")
    assert _vru_xy(trace, 10.0 / 1.5) == pytest.approx((x, y), abs=DISTANCE_TOL_M)


@settings(max_examples=40, deadline=None)
@given(
    k0=st.floats(-0.3, 0.3),
    k1=st.floats(-0.3, 0.3),
    length=st.floats(0.5, 40.0),
    h0=st.floats(-math.pi, math.pi),
)
def test_sampled_clothoid_end_poses_match_quadrature(k0: float, k1: float, length: float, h0: float):
    poses = clothoid_poses(WorldPose(1.0, -2.0, h0), k0, k1, length)

    def heading(s: float) -> float:
        return h0 + k0 * s + (k1 - k0) * s * s / (2 * length)

    x = 1.0 + quad(lambda s: math.cos(heading(s)), 0.0, length, epsabs=1e-12, epsrel=1e-12, limit=200)[0]
    y = -2.0 + quad(lambda s: math.sin(heading(s)), 0.0, length, epsabs=1e-12, epsrel=1e-12, limit=200)[0]
    assert (poses[-1].x_m, poses[-1].y_m) == pytest.approx((x, y), abs=1e-6)
    assert poses[-1].heading_rad == pytest.approx(heading(length), abs=1e-9)
    gaps = np.hypot(np.diff([p.x_m for p in poses]), np.diff([p.y_m for p in poses]))
    assert gaps.max() <= 0.2 + 1e-9


def test_a_clothoid_spline_ends_at_its_quadrature_end_pose():
    def heading(s: float) -> float:  # 0 -> 0.1 1/m over 10 m, then back to 0 over 10 m, from north
        first = 0.01 * min(s, 10.0) ** 2 / 2
        rest = max(s - 10.0, 0.0)
        return math.pi / 2 + first + 0.1 * rest - 0.01 * rest**2 / 2

    x = quad(lambda s: math.cos(heading(s)), 0.0, 20.0, points=[10.0], epsabs=1e-12)[0]
    y = -6.0 + quad(lambda s: math.sin(heading(s)), 0.0, 20.0, points=[10.0], epsabs=1e-12)[0]
    scenario = read_xosc(DATA / "vru_clothoid_spline.xosc")
    end = scenario.vrus[0].path[-2]
    assert (end.x_m, end.y_m) == pytest.approx((x, y), abs=1e-9)
    trace = _trace(DATA / "vru_clothoid_spline.xosc")
    assert _vru_xy(trace, 10.0) == pytest.approx((x, y), abs=DISTANCE_TOL_M)
    assert _vru_xy(trace, 5.0) == pytest.approx(
        (quad(lambda s: math.cos(heading(s)), 0, 10)[0], -6.0 + quad(lambda s: math.sin(heading(s)), 0, 10)[0]),
        abs=DISTANCE_TOL_M,
    )


def test_a_spline_segments_heading_offset_turns_its_start(tmp_path):
    path = _edited(
        tmp_path,
        "vru_clothoid_spline.xosc",
        '<ClothoidSplineSegment curvatureStart="0.1" curvatureEnd="0.0" length="10.0"/>',
        '<ClothoidSplineSegment curvatureStart="0.1" curvatureEnd="0.0" length="10.0" hOffset="-0.3"/>',
    )

    def heading(s: float) -> float:
        first = 0.01 * min(s, 10.0) ** 2 / 2
        rest = max(s - 10.0, 0.0)
        return math.pi / 2 + first + (-0.3 + 0.1 * rest - 0.01 * rest**2 / 2 if s > 10.0 else 0.0)

    x = quad(lambda s: math.cos(heading(s)), 0.0, 20.0, points=[10.0], epsabs=1e-12)[0]
    y = -6.0 + quad(lambda s: math.sin(heading(s)), 0.0, 20.0, points=[10.0], epsabs=1e-12)[0]
    end = read_xosc(path).vrus[0].path[-2]
    assert (end.x_m, end.y_m) == pytest.approx((x, y), abs=1e-9)


# --------------------------------------------------------------------------------------------- timing


def test_a_timed_vru_stands_until_its_first_time_then_moves_at_one_speed():
    scenario = read_xosc(DATA / "vru_timing.xosc")
    vru = scenario.vrus[0]
    assert vru.trigger.at_time_s == pytest.approx(2.0) and vru.top_speed_mps == pytest.approx(1.5)
    trace = _trace(DATA / "vru_timing.xosc")
    assert _vru_xy(trace, 1.9) == pytest.approx((0.0, -6.0), abs=1e-9)
    assert _vru_xy(trace, 3.0) == pytest.approx((0.0, -4.5), abs=DISTANCE_TOL_M)
    assert _vru_xy(trace, 4.0) == pytest.approx((0.0, -3.0), abs=DISTANCE_TOL_M)  # the second vertex at its time
    assert _vru_xy(trace, 5.0) == pytest.approx((1.5, -3.0), abs=DISTANCE_TOL_M)


def test_a_timed_clothoid_stands_then_reaches_its_end_at_its_stop_time(tmp_path):
    path = _edited(tmp_path, "vru_clothoid.xosc", 'length="10.0">', 'length="10.0" startTime="2" stopTime="7">')
    text = path.read_text()
    head, _, tail = text.rpartition("<TimeReference><None/>")
    path.write_text(head + '<TimeReference><Timing domainAbsoluteRelative="absolute" scale="1" offset="0"/>' + tail)
    edited = path.read_text().replace('<AbsoluteTargetSpeed value="1.5"/>', '<AbsoluteTargetSpeed value="0.0"/>')
    path.write_text(edited)
    vru = read_xosc(path).vrus[0]
    assert (vru.trigger.at_time_s, vru.top_speed_mps) == pytest.approx((2.0, 2.0), abs=1e-3)  # along the chords
    x, y, _ = _fresnel_end(0.0, -6.0, math.pi / 2, 0.02, 10.0)
    trace = _trace(path)
    assert _vru_xy(trace, 1.9) == pytest.approx((0.0, -6.0), abs=1e-9)
    assert _vru_xy(trace, 7.0) == pytest.approx((x, y), abs=DISTANCE_TOL_M)


def test_a_timed_spline_from_t_0_starts_at_its_speed(tmp_path):
    path = _edited(
        tmp_path,
        "vru_clothoid_spline.xosc",
        'curvatureEnd="0.1" length="10.0">',
        'curvatureEnd="0.1" length="10.0" timeStart="0">',
    )
    text = path.read_text().replace(
        'curvatureEnd="0.0" length="10.0"/>', 'curvatureEnd="0.0" length="10.0" timeStart="4"/>'
    )
    text = text.replace("<ClothoidSpline>", '<ClothoidSpline timeEnd="8">')
    head, _, tail = text.rpartition("<TimeReference><None/>")
    path.write_text(head + '<TimeReference><Timing domainAbsoluteRelative="relative" scale="1" offset="0"/>' + tail)
    vru = read_xosc(path).vrus[0]
    assert (vru.initial_speed_mps, vru.top_speed_mps) == pytest.approx((2.5, 2.5), abs=1e-3)  # 20 m in 8 s
    uneven = path.read_text().replace('timeStart="4"', 'timeStart="3"')
    path.write_text(uneven)
    refused_at(path, 'timeStart="0"', "<ClothoidSplineSegment>", "one constant speed")  # the first one off its time


def test_an_ego_timed_at_its_cruise_speed_is_accepted():
    scenario = read_xosc(DATA / "ego_timing.xosc")
    assert scenario.ego.cruise_speed_mps == 10.0 and scenario.ego.route.length_m == pytest.approx(60.0)


def test_timing_off_one_speed_is_refused_naming_the_vertex(tmp_path):
    path = _edited(tmp_path, "vru_timing.xosc", 'time="1.5"', 'time="1.2"')
    refused_at(path, 'time="1.2"', "<Vertex>", "one constant speed")


def test_an_ego_timed_off_its_cruise_speed_isrefused_at(tmp_path):
    path = _edited(
        tmp_path, "ego_timing.xosc", '<AbsoluteTargetSpeed value="10.0"/>', '<AbsoluteTargetSpeed value="12.0"/>'
    )
    refused_at(path, 'time="7"', "<Vertex>", "cruise speed")


@pytest.mark.parametrize(
    ("old", "new", "marker", "words"),
    [
        (' time="1.5"', "", '<WorldPosition x="0.0" y="-3.0"', ("<Vertex>", "no time")),
        ('scale="2.0"', 'scale="0"', "<Timing", ("<Timing>", "scale")),
        ('offset="1.0"', 'offset="-2.0"', 'time="0.5"', ("<Vertex>", "t >= 0")),
    ],
)
def test_timing_refusals(tmp_path, old, new, marker, words):
    refused_at(_edited(tmp_path, "vru_timing.xosc", old, new), marker, *words)


LIMIT_WORDS = ("exceeds the limit of 10,000,000,000", "VRUSIM_LIMIT_XML_NUMBER")


@pytest.mark.parametrize(
    ("name", "old", "new", "marker", "words"),
    [
        ("vru_clothoid.xosc", 'curvature="0.0"', 'curvature="1e308"', "<Clothoid ", ("<Clothoid> attribute curvature",
         *LIMIT_WORDS)),
        ("vru_clothoid.xosc", 'curvaturePrime="0.02" length="10.0"', 'curvaturePrime="0.0" length="1e12"',
         "<Clothoid ", ("<Clothoid> attribute length", *LIMIT_WORDS)),
        ("vru_clothoid.xosc", 'length="10.0"', 'length="1e6"', "<Clothoid ",
         ("<Clothoid> attribute length: 1,000,000 m exceeds the limit of 100,000", "VRUSIM_LIMIT_LENGTH_M")),
        ("vru_clothoid_spline.xosc", 'curvatureEnd="0.0" length="10.0"', 'curvatureEnd="0.0" length="99995"',
         'curvatureEnd="0.0"', ("<ClothoidSplineSegment> attribute length (with the segments before it): 100,005 m",
                                "VRUSIM_LIMIT_LENGTH_M")),
        ("vru_timing.xosc", 'scale="2.0"', 'scale="1e308"', "<Timing", ("<Timing> attribute scale", *LIMIT_WORDS)),
        ("vru_timing.xosc", 'time="2.5"', 'time="1e308"', 'time="1e308"', ("<Vertex> attribute time", *LIMIT_WORDS)),
        ("vru_timing.xosc", 'x="3.0" y="-3.0" h="0.0"', 'x="0.0" y="-6.0" h="0.0"', 'time="2.5"',
         ("<Vertex> ends where the trajectory starts",)),
    ],
)  # fmt: skip
def test_huge_numbers_and_lengths_are_refused_at_their_attribute(tmp_path, name, old, new, marker, words):
    """A clothoid 1e12 m long allocated 36 TiB of samples (MemoryError), curvature 1e308 was a math domain error,
    a time or time scale of 1e308 (or a timed trajectory standing still) a ZeroDivisionError."""
    path = _edited(tmp_path, name, old, new)
    if name == "vru_timing.xosc" and 'y="-6.0" h="0.0"' in new:
        edited(path, 'x="0.0" y="-3.0"', 'x="0.0" y="-6.0"')
    refused_at(path, marker, *words)


def test_a_timed_vru_with_speed_events_isrefused_at(tmp_path):
    path = _copy(tmp_path, "vru_timing.xosc")
    text = path.read_text()
    event = text.index('<Event name="vru0_move"')
    speed = """<Action name="walk"><PrivateAction><LongitudinalAction><SpeedAction>
      <SpeedActionDynamics dynamicsShape="step" dynamicsDimension="time" value="0.0"/>
      <SpeedActionTarget><AbsoluteTargetSpeed value="1.0"/></SpeedActionTarget>
    </SpeedAction></LongitudinalAction></PrivateAction></Action>"""
    anchor = text.index("<Action ", event)
    path.write_text(text[:anchor] + speed + text[anchor:])
    refused_at(path, '<Action name="walk">', "timed trajectory")


# --------------------------------------------------------------------------------------------- relative positions


def test_teleports_relative_to_entities_placed_earlier():
    vrus = read_xosc(DATA / "relative_positions.xosc").vrus
    starts = [(v.start.x_m, v.start.y_m) for v in vrus]
    assert starts[0] == pytest.approx((-20.0, -6.75))  # ego (-40, -1.75) heading 0, dx 20, dy -5
    assert vrus[0].heading_deg == pytest.approx(90.0)  # relative orientation added to the ego's heading
    assert starts[1] == pytest.approx((-19.0, -7.25))  # world axes from vru0
    assert starts[2] == pytest.approx((-35.0, 1.75 + 0.25))  # lane 1's centre, 5 m on, 0.25 m left of it
    assert vrus[2].heading_deg == pytest.approx(0.0)
    assert starts[3] == pytest.approx((-30.0, -4.75))  # ds 10, dt -3 from t = -1.75
    assert starts[4] == pytest.approx(_on_turn(1.0), abs=1e-9)  # lane -1 of the arc road at s = 10.25 (1 rad)
    assert starts[5] == pytest.approx(_on_turn(1.0 + 3.0 / RADIUS_M), abs=1e-6)  # 3 m on along the lane centre
    assert vrus[5].heading_deg == pytest.approx(math.degrees(0.5))  # absolute orientation


@pytest.mark.parametrize(
    ("lane", "d_lane", "expected"),
    [(-1, 1, 1), (-1, 2, 2), (1, -1, -1), (1, -2, -2), (-2, 2, 1), (-1, -1, -2), (2, 0, 2)],
)
def test_relative_lanes_skip_the_centre_lane(lane, d_lane, expected):
    assert relative_lane_id(lane, d_lane) == expected


@pytest.mark.parametrize(
    ("old", "new", "marker", "words"),
    [
        (
            'entityRef="vru0" dx="1.0"',
            'entityRef="vru3" dx="1.0"',
            'entityRef="vru3"',
            ("<RelativeWorldPosition>", "placed earlier"),
        ),
        (
            'dLane="1" ds="5.0"',
            'dLane="1" ds="5.0" dsLane="5.0"',
            'dsLane="5.0"',
            ("<RelativeLanePosition>", "ds and dsLane"),
        ),
        ('ds="10.0" dt="-3.0"', 'ds="100.0" dt="-3.0"', 'ds="100.0"', ("<RelativeRoadPosition>", "outside the road")),
        ('dLane="1" ds="5.0"', 'dLane="3" ds="5.0"', 'dLane="3"', ("<RelativeLanePosition>", "no lane 3")),
    ],
)
def test_relative_position_refusals(tmp_path, old, new, marker, words):
    refused_at(_edited(tmp_path, "relative_positions.xosc", old, new), marker, *words)


# --------------------------------------------------------------------------------------------- refusals


@pytest.mark.parametrize(
    ("name", "old", "new", "marker", "words"),
    [
        (
            "ego_route_junction.xosc",
            'routeStrategy="shortest"',
            'routeStrategy="random"',
            'routeStrategy="random"',
            ("<Waypoint>", "random"),
        ),
        (
            "ego_route_junction.xosc",
            '<Route name="route" closed="false">',
            '<Route name="route" closed="true">',
            "<Route ",
            ("<Route>", "closed"),
        ),
        (
            "ego_route_junction.xosc",
            'roadId="2" laneId="-1" s="30.0"',
            'roadId="1" laneId="-1" s="5.0"',
            "<Route ",
            ("<Route>", "no lane route"),
        ),
        (
            "ego_route_junction.xosc",
            'roadId="2" laneId="-1" s="30.0"',
            'roadId="2" laneId="1" s="30.0"',
            "<Route ",
            ("<Route>", "no lane route"),
        ),
        (
            "ego_route_junction.xosc",
            'roadId="2" laneId="-1" s="30.0"',
            'roadId="9" laneId="-1" s="30.0"',
            'roadId="9"',
            ("<LanePosition>", "no road '9'"),
        ),
        (
            "ego_route_catalog.xosc",
            'entryName="left_turn"',
            'entryName="u_turn"',
            "<CatalogReference",
            ("<CatalogReference>", "u_turn"),
        ),
        (
            "vru_route_junction.xosc",
            '<Waypoint routeStrategy="shortest"><Position><LanePosition roadId="2" laneId="-1" s="10.0" offset="0.0"/>',
            '<Waypoint routeStrategy="shortest"><Position><WorldPosition x="40" y="40"/>',
            'x="40" y="40"',
            ("<Waypoint>", "lies on no lane"),
        ),
        (
            "vru_clothoid.xosc",
            'curvaturePrime="0.02"',
            'curvaturePrime="0.02" curvatureDot="0.02"',
            "<Clothoid ",
            ("<Clothoid>", "curvatureDot"),
        ),
        ("vru_clothoid.xosc", 'length="10.0"', 'length="0"', "<Clothoid ", ("<Clothoid>", "length")),
        (
            "vru_clothoid_spline.xosc",
            '<ClothoidSplineSegment curvatureStart="0.1" curvatureEnd="0.0" length="10.0"/>',
            '<ClothoidSplineSegment curvatureStart="0.1" curvatureEnd="0.0" length="10.0">'
            '<PositionStart><WorldPosition x="5" y="5"/></PositionStart></ClothoidSplineSegment>',
            '<PositionStart><WorldPosition x="5"',
            ("<PositionStart>", "cannot jump"),
        ),
        (
            "vru_clothoid_spline.xosc",
            "LAST:<TimeReference><None/>",
            '<TimeReference><Timing domainAbsoluteRelative="absolute" scale="1" offset="0"/>',
            '<ClothoidSplineSegment curvatureStart="0.0"',
            ("<ClothoidSplineSegment>", "no time"),
        ),
        (
            "ego_route_junction.xosc",
            '<Route name="route" closed="false">',
            '<Route name="route" closed="false"><ParameterDeclarations>'
            '<ParameterDeclaration name="a" parameterType="double" value="1"/></ParameterDeclarations>',
            "<Route ",
            ("<ParameterDeclarations>", "inline route"),
        ),
    ],
)
def test_refusals_name_the_element_and_its_line(tmp_path, name, old, new, marker, words):
    refused_at(_edited(tmp_path, name, old, new), marker, *words)


def test_an_ego_clothoid_that_is_not_line_turn_line_isrefused_at(tmp_path):
    path = _copy(tmp_path, "vru_clothoid.xosc")
    text = path.read_text()
    ego_route = text[text.index("<FollowTrajectoryAction>") : text.index("</FollowTrajectoryAction>")]
    clothoid = text[text.index("<Clothoid ") : text.index("</Clothoid>") + len("</Clothoid>")]
    clothoid = clothoid.replace('x="0.0" y="-6.0" h="1.5707963267948966"', 'x="-45.0" y="1.75" h="3.141592653589793"')
    shape = ego_route[ego_route.index("<Polyline>") : ego_route.index("</Polyline>") + len("</Polyline>")]
    path.write_text(text.replace(shape, clothoid, 1))
    refused_at(path, "<PrivateAction><RoutingAction>", "ego's trajectory", "clothoid")
