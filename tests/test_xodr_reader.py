"""OpenDRIVE import: reference lines against analytic and numerically integrated curves, lane positions, files
vrusim exported itself, routes through a junction, and hostile or malformed files."""

from __future__ import annotations

import math
import os
import re
import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy.integrate import quad
from scipy.special import fresnel

from vrusim.errors import UserInputError
from vrusim.formats.xodr_geometry import reference_poses
from vrusim.formats.xodr_lane_graph import junction_cost, shortest_lanes, successors
from vrusim.formats.xodr_lanes import lane_borders_t, lane_position, road_position
from vrusim.formats.xodr_projection import lane_at, project, road_coordinates
from vrusim.formats.xodr_reader import parse_xodr, read_xodr
from vrusim.formats.xodr_route import reference_points, route_polyline
from vrusim.geometry.paths import sample_polyline
from vrusim.interop.openscenario import export_openscenario, file_stem, road_half_length_m
from vrusim.ncap.build import build_test
from vrusim.ncap.grid import select

DATA = Path(__file__).resolve().parent / "data" / "xodr"
TOL = 1e-9


@pytest.fixture(scope="module")
def analytic():
    return read_xodr(DATA / "analytic.xodr")


def pose_at(network, road_id: str, s: float) -> tuple[float, float, float]:
    x, y, heading = reference_poses(network.roads[road_id], s)
    return float(x[0]), float(y[0]), float(heading[0])


def integrated_end(x0: float, y0: float, hdg: float, k0: float, k1: float, length: float) -> tuple[float, float]:
    """End point of a curve with curvature linear from k0 to k1 over `length`, by adaptive quadrature (scipy)."""

    def heading(s: float) -> float:
        return hdg + k0 * s + (k1 - k0) * s * s / (2 * length)

    dx = quad(lambda s: math.cos(heading(s)), 0, length, epsabs=1e-12, epsrel=1e-12, limit=200)[0]
    dy = quad(lambda s: math.sin(heading(s)), 0, length, epsabs=1e-12, epsrel=1e-12, limit=200)[0]
    return x0 + dx, y0 + dy


def parabola_arc_m(c: float, u: float) -> float:
    """Arc length of v = c u^2 from 0 to u (closed form)."""
    return u * math.sqrt(1 + 4 * c * c * u * u) / 2 + math.asinh(2 * c * u) / (4 * c)


def one_road(geometry: str, length: float, x="0", y="0", hdg="0", lanes: str = "") -> str:
    """An OpenDRIVE document of one road with one geometry element `geometry` (and optional lane XML)."""
    lanes = lanes or '<laneSection s="0"><center><lane id="0"/></center></laneSection>'
    return (
        f'<OpenDRIVE><header revMajor="1" revMinor="6"/><road id="r" length="{length!r}" junction="-1"><planView>'
        f'<geometry s="0" x="{x}" y="{y}" hdg="{hdg}" length="{length!r}">{geometry}</geometry></planView>'
        f"<lanes>{lanes}</lanes></road></OpenDRIVE>"
    )


# ---------------------------------------------------------------------------------------------- the reader


def test_the_reader_keeps_every_record_of_the_file(analytic):
    assert (analytic.rev_major, analytic.rev_minor) == (1, 6)
    assert list(analytic.roads) == ["line", "arc", "spiral", "clothoid", "poly3", "ppoly_line", "ppoly_parabola"]
    arc = analytic.roads["arc"]
    assert arc.geometries[0].shape.curvature_per_m == 0.05
    assert [section.s_m for section in arc.sections] == [0.0, 12.0]
    assert [lane.id for lane in arc.sections[0].right] == [-1, -2]  # ordered outward whatever the file order
    assert [w.s_m for w in arc.sections[0].right[1].widths] == [0.0, 10.0]
    assert arc.lane_offsets[0].a == 0.25
    assert analytic.roads["ppoly_line"].geometries[0].shape.normalized is False
    assert analytic.roads["ppoly_parabola"].geometries[0].shape.normalized is True
    lines = (DATA / "analytic.xodr").read_text().splitlines()
    assert 'curvature="0.05"' in lines[arc.geometries[0].line - 1]  # line numbers are kept for messages


# ------------------------------------------------------------------------------------- analytic reference lines


def test_a_line_ends_length_along_its_heading(analytic):
    x, y, heading = pose_at(analytic, "line", 10.0)
    assert (x, y, heading) == pytest.approx((1 + 10 * math.cos(0.3), 2 + 10 * math.sin(0.3), 0.3), abs=TOL)


def test_an_arc_stays_on_its_circle_and_ends_at_the_turned_pose(analytic):
    radius, centre = 20.0, np.array([0.0, 20.0])  # curvature 0.05, start (0, 0) heading 0: centre to the left
    x, y, heading = reference_poses(analytic.roads["arc"], np.linspace(0, 15, 31))
    assert np.hypot(x - centre[0], y - centre[1]) == pytest.approx(np.full(31, radius), abs=TOL)
    angle = 15 / radius
    assert (x[-1], y[-1], heading[-1]) == pytest.approx(
        (radius * math.sin(angle), radius * (1 - math.cos(angle)), angle)
    )


def test_a_spiral_turns_by_its_mean_curvature_and_ends_where_quadrature_says(analytic):
    x, y, heading = pose_at(analytic, "spiral", 40.0)
    assert heading == pytest.approx(-0.7 + 40 * (0.01 - 0.05) / 2, abs=TOL)
    assert (x, y) == pytest.approx(integrated_end(5, -3, -0.7, 0.01, -0.05, 40), abs=1e-9)


def test_a_clothoid_from_zero_curvature_follows_the_fresnel_integrals(analytic):
    scale = math.sqrt(math.pi * 50 / 0.04)  # heading (pi / 2) (s / scale)^2 = 0.04 s^2 / (2 * 50)
    stations = np.array([0.0, 7.3, 25.0, 50.0])
    x, y, _ = reference_poses(analytic.roads["clothoid"], stations)
    fresnel_s, fresnel_c = fresnel(stations / scale)
    assert x == pytest.approx(scale * fresnel_c, abs=1e-9)
    assert y == pytest.approx(scale * fresnel_s, abs=1e-9)


def test_poly3_measures_s_as_arc_length_along_the_cubic(analytic):
    for u in (0.0, 4.0, 10.0):
        x, y, heading = pose_at(analytic, "poly3", parabola_arc_m(0.05, u) if u else 0.0)
        assert (x, y, heading) == pytest.approx((u, 0.05 * u * u, math.atan(0.1 * u)), abs=1e-9)


def test_a_param_poly3_over_arc_length_can_be_a_straight_line(analytic):
    x, y, heading = pose_at(analytic, "ppoly_line", 7.0)
    assert (x, y, heading) == pytest.approx((-4 + 7 * math.cos(1), 6 + 7 * math.sin(1), 1.0), abs=TOL)


def test_a_normalized_param_poly3_maps_s_to_p_linearly(analytic):
    length = analytic.roads["ppoly_parabola"].length_m  # u = 10 p, v = 5 p^2: the parabola v = 0.05 u^2
    x, y, heading = pose_at(analytic, "ppoly_parabola", length / 2)  # p = 0.5, not half the arc length
    assert (x, y, heading) == pytest.approx((5.0, 1.25, math.atan(0.5)), abs=TOL)
    assert pose_at(analytic, "ppoly_parabola", length) == pytest.approx(pose_at(analytic, "poly3", length), abs=1e-9)


# ------------------------------------------------------------------------------------------- lane positions


def right_outer_width(s: float) -> float:
    """Width of lane -2 of road "arc" (the file's records written out): the cubic to sOffset 10, then 3 m."""
    return 2 + 0.1 * s - 0.01 * s**2 + 0.0005 * s**3 if s < 10 else 3.0


@pytest.mark.parametrize("lane, s", [(1, 6.0), (-1, 6.0), (-2, 4.0), (-2, 11.0), (-1, 13.5)])
def test_a_lane_centre_on_an_arc_road_lies_on_the_circle_of_radius_minus_its_t(analytic, lane, s):
    offset = 0.25
    inner_right = 3.5 if s < 12 else 3.5 + 0.1 * (s - 12)  # the second section's record starts at its start
    t = {1: offset + 1.5, -1: offset - inner_right / 2, -2: offset - 3.5 - right_outer_width(s) / 2}[lane]
    for extra in (0.0, 0.4):
        x, y, heading = lane_position(analytic, "arc", lane, s, offset_m=extra)
        radius, angle = 20.0 - (t + extra), s / 20.0
        assert (x[0], y[0], heading[0]) == pytest.approx(
            (radius * math.sin(angle), 20 - radius * math.cos(angle), angle)
        )


def test_the_lane_offset_is_zero_before_its_first_record_and_a_cubic_after_it(analytic):
    stations = np.array([0.0, 3.9, 4.0, 8.0])
    offset = np.where(stations < 4, 0.0, -0.5 + 0.05 * (stations - 4))
    x, y, heading = lane_position(analytic, "line", -1, stations)
    assert heading == pytest.approx(np.full(4, 0.3))  # the s axis's, whatever the offset's slope
    t = offset - 1.5  # the centre of a 3 m right lane
    assert x == pytest.approx(1 + stations * math.cos(0.3) - t * math.sin(0.3))  # a line from (1, 2) at 0.3 rad
    assert y == pytest.approx(2 + stations * math.sin(0.3) + t * math.cos(0.3))


def test_lane_borders_meet_and_a_lane_missing_from_a_section_is_refused(analytic):
    road = analytic.roads["arc"]
    stations = np.linspace(0, 11.9, 25)
    inner_1, outer_1 = lane_borders_t(road, -1, stations)
    inner_2, outer_2 = lane_borders_t(road, -2, stations)
    assert inner_1 == pytest.approx(np.full(25, 0.25)) and outer_1 == pytest.approx(inner_2)
    assert outer_2 - inner_2 == pytest.approx([-right_outer_width(s) for s in stations])
    with pytest.raises(UserInputError, match=r"road 'arc': no lane -2 in the lane section at s = 12 m"):
        lane_position(analytic, "arc", -2, 13.0)


def test_road_positions_off_the_road_or_on_no_road_are_user_errors(analytic):
    with pytest.raises(UserInputError, match=r"road 'line': station s = 10.5 m is outside the road \(0 to 10 m\)"):
        road_position(analytic, "line", 10.5)
    with pytest.raises(UserInputError, match="no road 'nowhere'"):
        road_position(analytic, "nowhere", 1.0)
    x, y, _ = road_position(analytic, "line", 10 + 1e-7, t_m=-2.0)  # round-off past the end is clamped
    assert (x[0], y[0]) == pytest.approx(
        (1 + 10 * math.cos(0.3) + 2 * math.sin(0.3), 2 + 10 * math.sin(0.3) - 2 * math.cos(0.3))
    )


@pytest.mark.parametrize(
    "rule, lane, forward", [("RHT", -1, True), ("RHT", 1, False), ("LHT", -1, False), ("LHT", 1, True)]
)
def test_a_lane_route_runs_in_the_direction_of_travel_of_its_rule(rule, lane, forward):
    lanes = (
        '<laneSection s="0"><left><lane id="1"><width sOffset="0" a="3" b="0" c="0" d="0"/></lane></left>'
        '<center><lane id="0"/></center><right><lane id="-1"><width sOffset="0" a="3" b="0" c="0" d="0"/></lane>'
        "</right></laneSection>"
    )
    network = parse_xodr(one_road("<line/>", 8.0, lanes=lanes).replace('junction="-1"', f'junction="-1" rule="{rule}"'))
    points = np.array(route_polyline(network, [("r", lane)], spacing_m=1.0).points)
    assert len(points) == 9 and points[:, 1] == pytest.approx(np.full(9, 1.5 * lane))
    assert points[[0, -1], 0] == pytest.approx([0.0, 8.0] if forward else [8.0, 0.0])


# ----------------------------------------------------------------------------------------- property tests


@given(
    k0=st.floats(-0.2, 0.2),
    k1=st.floats(-0.2, 0.2),
    length=st.floats(0.5, 80.0),
    hdg=st.floats(-math.pi, math.pi),
    arc=st.booleans(),
)
def test_arcs_and_spirals_end_where_numeric_integration_ends(k0, k1, length, hdg, arc):
    k1 = k0 if arc else k1
    shape = f'<arc curvature="{k0!r}"/>' if arc else f'<spiral curvStart="{k0!r}" curvEnd="{k1!r}"/>'
    network = parse_xodr(one_road(shape, length, x="3", y="-2", hdg=repr(hdg)))
    x, y, heading = pose_at(network, "r", length)
    assert heading == pytest.approx(hdg + length * (k0 + k1) / 2, abs=1e-12)
    assert (x, y) == pytest.approx(integrated_end(3, -2, hdg, k0, k1, length), abs=1e-8)


@given(
    coefficients=st.tuples(st.floats(-1, 1), st.floats(-1, 1), st.floats(-0.1, 0.1), st.floats(-0.01, 0.01)),
    length=st.floats(0.5, 40.0),
    fraction=st.floats(0.0, 1.0),
)
def test_a_poly3_point_at_s_is_s_along_the_curve(coefficients, length, fraction):
    a, b, c, d = coefficients
    network = parse_xodr(one_road(f'<poly3 a="{a!r}" b="{b!r}" c="{c!r}" d="{d!r}"/>', length, hdg="0"))
    x, y, _ = pose_at(network, "r", fraction * length)  # heading 0: u = x, v = y
    assert y == pytest.approx(a + b * x + c * x**2 + d * x**3, abs=1e-9)
    arc = quad(lambda u: math.sqrt(1 + (b + 2 * c * u + 3 * d * u * u) ** 2), 0, x, epsabs=1e-10, epsrel=1e-10)[0]
    assert arc == pytest.approx(fraction * length, abs=1e-8)


# ------------------------------------------------------------------------------- files vrusim exported itself


def exported_network(code: str, folder: Path):
    scenario = build_test(select(codes=[code])[0]).scenario
    export_openscenario(scenario, folder)
    return scenario, read_xodr(folder / f"{file_stem(scenario.name)}.xodr")


def test_an_exported_straight_road_reads_back_as_the_road_vrusim_drew(tmp_path):
    scenario, network = exported_network("CPNA", tmp_path)
    half, width = road_half_length_m(scenario), scenario.road.lane_width_m
    assert scenario.road.layout == "straight" and list(network.roads) == ["1"]
    points = reference_points(network.roads["1"], spacing_m=5.0)
    assert points[[0, -1]] == pytest.approx(np.array([[-half, 0.0], [half, 0.0]]), abs=TOL)
    assert np.abs(points[:, 1]).max() < TOL
    x, y, _ = lane_position(network, "1", -1, [0.0, 2 * half])  # right-hand traffic: the lane y < 0 drives +x
    assert np.column_stack([x, y]) == pytest.approx(np.array([[-half, -width / 2], [half, -width / 2]]), abs=TOL)


@pytest.fixture(scope="module")
def junction(tmp_path_factory):
    return exported_network("CPTAfs", tmp_path_factory.mktemp("xodr"))


def test_an_exported_junction_has_the_arms_vrusim_drew_and_connected_geometry(junction):
    scenario, network = junction
    half, width = road_half_length_m(scenario), scenario.road.lane_width_m
    arms = {"1": ((-half, 0), (-width, 0)), "2": ((width, 0), (half, 0)), "3": ((0, -half), (0, -width)),
            "4": ((0, width), (0, half))}  # fmt: skip
    for road_id, ends in arms.items():
        x, y, _ = reference_poses(network.roads[road_id], [0.0, network.roads[road_id].length_m])
        assert np.column_stack([x, y]) == pytest.approx(np.array(ends, dtype=float), abs=1e-9)
    connecting = [road for road in network.roads.values() if road.junction != "-1"]
    assert len(connecting) == 6 and {c.connecting_road for c in network.junctions["100"].connections} == {
        road.id for road in connecting
    }
    for road in network.roads.values():  # each geometry starts where the previous one ends (spirals here)
        for after in road.geometries[1:]:
            end = pose_at(network, road.id, after.s_m - 1e-12)
            assert end == pytest.approx((after.x_m, after.y_m, after.hdg_rad), abs=1e-7)
    for road in connecting:  # and each connecting road meets its arms
        for link, s in ((road.predecessor, 0.0), (road.successor, road.length_m)):
            arm = network.roads[link.element_id]
            at = pose_at(network, road.id, s)[:2]
            assert at == pytest.approx(
                pose_at(network, arm.id, 0.0 if link.contact_point == "start" else arm.length_m)[:2], abs=1e-7
            )


def test_a_route_through_the_junction_is_a_polyline_along_the_lane_centres(junction):
    scenario, network = junction
    half, width = road_half_length_m(scenario), scenario.road.lane_width_m
    left_turn = next(c for c in network.junctions["100"].connections if c.incoming_road == "1" and
                     network.roads[c.connecting_road].successor.element_id == "4").connecting_road  # fmt: skip
    route = route_polyline(network, [("1", -1), (left_turn, -1), ("4", -1)])
    assert route.points[0] == pytest.approx((-half, -width / 2)) and route.points[-1] == pytest.approx(
        (width / 2, half)
    )
    samples = sample_polyline(route)
    assert np.isfinite(samples).all()
    # the arms' straight lanes, then the turn's lane centre at t = -w/2 (outside a 90 degree left turn): the
    # reference line's length + w/2 * pi/2 (length of a parallel curve: integral of 1 - curvature * t)
    turn_m = network.roads[left_turn].length_m + width / 2 * math.pi / 2
    assert route.length_m == pytest.approx(2 * (half - width) + turn_m, abs=2e-3)  # chords: 1.3 mm short
    fine = route_polyline(network, [("1", -1), (left_turn, -1), ("4", -1)], spacing_m=0.02)
    assert fine.length_m == pytest.approx(2 * (half - width) + turn_m, abs=2e-5)
    with pytest.raises(UserInputError, match=r"route: road '4' lane -1 starts .* m from the end of the previous step"):
        route_polyline(network, [("1", -1), ("4", -1)])
    with pytest.raises(UserInputError, match="no road '99'"):
        route_polyline(network, [("1", -1), ("99", -1)])


def test_the_lane_graph_finds_the_exported_left_turn(junction):
    _, network = junction
    left_turn = next(c for c in network.junctions["100"].connections if c.incoming_road == "1" and
                     network.roads[c.connecting_road].successor.element_id == "4").connecting_road  # fmt: skip
    assert shortest_lanes(network, ("1", -1), ("4", -1)) == [("1", -1), (left_turn, -1), ("4", -1)]
    assert all(network.roads[road].junction != "-1" for road, _ in successors(network, ("1", -1)))
    with pytest.raises(UserInputError, match="no lane route"):
        shortest_lanes(network, ("4", -1), ("1", -1))  # lane -1 of arm 4 leaves the junction


def _two_roads(contact: str, lane_link: str = "") -> str:
    """Road a (east from the origin, 10 m) linked at its end to road b at b's `contact` end; b ends (contact
    "end") or starts (contact "start") where a ends."""
    lanes = (
        '<lanes><laneSection s="0"><left><lane id="1"><width sOffset="0" a="3" b="0" c="0" d="0"/></lane></left>'
        '<center><lane id="0"/></center><right><lane id="-1">{link}<width sOffset="0" a="3" b="0" c="0" d="0"/>'
        "</lane></right></laneSection></lanes>"
    )
    b_start, b_hdg = ("10", "0") if contact == "start" else ("20", repr(math.pi))
    return (
        '<OpenDRIVE><header revMajor="1" revMinor="6"/>'
        '<road id="a" length="10" junction="-1"><link>'
        f'<successor elementType="road" elementId="b" contactPoint="{contact}"/></link><planView>'
        '<geometry s="0" x="0" y="0" hdg="0" length="10"><line/></geometry></planView>'
        f"{lanes.format(link=lane_link)}</road>"
        '<road id="b" length="10" junction="-1"><planView>'
        f'<geometry s="0" x="{b_start}" y="0" hdg="{b_hdg}" length="10"><line/></geometry></planView>'
        f"{lanes.format(link='')}</road></OpenDRIVE>"
    )


@pytest.mark.parametrize(
    ("contact", "lane_link", "expected"),
    [
        ("start", "", [("b", -1)]),  # same id, same direction
        ("end", "", [("b", 1)]),  # head to head: the opposite id keeps the driving side
        ("start", '<link><successor id="1"/></link>', []),  # its own link names a lane driven the other way
    ],
)
def test_road_links_lead_to_the_lane_on_the_same_side(contact, lane_link, expected):
    network = parse_xodr(_two_roads(contact, lane_link))
    assert successors(network, ("a", -1)) == expected


# ------------------------------------------------------------------------------------ world -> road projection

ROUTES = Path(__file__).resolve().parent / "data" / "xosc" / "routes"


def test_lane_links_are_read_and_followed():
    network = read_xodr(ROUTES / "junction.xodr")
    lane = network.roads["100"].sections[0].right[0]
    assert (lane.predecessors, lane.successors) == ((-1,), (-1,))
    assert successors(network, ("1", -1)) == [("100", -1), ("101", -1)]
    assert successors(network, ("100", -1)) == [("2", -1)]
    assert successors(network, ("2", -1)) == [] and successors(network, ("2", 1)) == []
    assert shortest_lanes(network, ("1", -1), ("3", -1), junction_cost) == [("1", -1), ("101", -1), ("3", -1)]


@given(s=st.floats(0.0, 10.0), t=st.floats(-2.9, 2.9))
def test_a_point_projects_back_to_its_road_position_on_a_line(analytic, s, t):
    road = analytic.roads["line"]
    x, y, _ = road_position(analytic, "line", s, t)
    found = road_coordinates(road, float(x[0]), float(y[0]))
    assert (found.s_m, found.t_m, found.heading_rad) == pytest.approx((s, t, 0.3), abs=1e-9)


@given(s=st.floats(0.0, 15.0), t=st.floats(-6.0, 6.0))
def test_a_point_projects_back_to_its_road_position_on_an_arc(analytic, s, t):
    """The arc road: radius 20 m about (0, 20); (s, t) is the point at angle s / 20 on the circle of radius 20 - t."""
    angle = s / 20.0
    x, y = (20.0 - t) * math.sin(angle), 20.0 - (20.0 - t) * math.cos(angle)
    found = road_coordinates(analytic.roads["arc"], x, y)
    assert (found.s_m, found.t_m, found.heading_rad) == pytest.approx((s, t, angle), abs=1e-9)
    assert found.distance_m == pytest.approx(0.0, abs=1e-9)


def test_the_lane_a_point_lies_in(analytic):
    road = analytic.roads["arc"]  # lane offset 0.25; lane 1: 3 m; lane -1: 3.5 m; lane -2 from -3.25 outward
    assert [lane_at(road, 6.0, t) for t in (3.0, 0.3, 0.2, -3.0, -3.4, -20.0)] == [1, 1, -1, -1, -2, None]
    network = read_xodr(ROUTES / "junction.xodr")
    assert project(network, -40.0, -1.0).road_id == "1" and project(network, -40.0, -1.0).lane_id == -1
    with pytest.raises(UserInputError, match="lies on no lane"):
        project(network, 40.0, 40.0)


# ------------------------------------------------------------------------------------ hostile and malformed


@pytest.mark.parametrize(
    "name, message",
    [
        ("billion_laughs.xodr", r"line 2: a document type declaration \(<!DOCTYPE>\) is not accepted"),
        ("external_entity.xodr", r"line 2: a document type declaration \(<!DOCTYPE>\) is not accepted"),
        ("missing_attribute.xodr", r"line 5: <geometry> has no attribute 'hdg'"),
        ("unknown_geometry.xodr", r"line 6: <cubicBezier> is not a supported geometry"),
    ],
)
def test_hostile_and_malformed_files_are_refused_naming_file_line_and_element(name, message):
    with pytest.raises(UserInputError, match=f"{name}: {message}"):
        read_xodr(DATA / name)


def test_a_file_over_the_size_limit_is_refused_before_parsing(tmp_path):
    path = tmp_path / "huge.xodr"
    text = (DATA / "analytic.xodr").read_text()
    path.write_text(text.replace("<OpenDRIVE>", "<OpenDRIVE><!--" + "x" * 2_000_000 + "-->", 1))
    with pytest.raises(UserInputError, match=r"huge.xodr: 2,\d{3},\d{3} bytes exceeds the limit of 2,000,000"):
        read_xodr(path)
    if hasattr(os, "mkfifo"):
        os.mkfifo(tmp_path / "fifo.xodr")
        with pytest.raises(UserInputError, match="not a regular file"):
            read_xodr(tmp_path / "fifo.xodr")
    with pytest.raises(UserInputError, match="no such OpenDRIVE file"):
        read_xodr(tmp_path / "missing.xodr")


CENTRE = '<center><lane id="0"/></center>'
ROAD = one_road("<line/>", 5.0)


@pytest.mark.parametrize(
    "text, message",
    [
        ("<OpenSCENARIO/>", r"line 1: <OpenSCENARIO> is not an OpenDRIVE document"),
        ("<OpenDRIVE><road>", r"line 1: not well-formed XML \(no element found\)"),
        (ROAD.replace('x="0"', 'x="east"'), r"<geometry> attribute x: expected a number, got 'east'"),
        (ROAD.replace('hdg="0"', 'hdg="nan"'), r"<geometry> attribute hdg: expected a finite number"),
        (one_road("<line/><arc curvature='1'/>", 5.0), r"<geometry> needs exactly one of line, arc, spiral"),
        (one_road('<paramPoly3 aU="0" bU="1" cU="0" dU="0" aV="0" bV="0" cV="0" dV="0" pRange="p"/>', 5.0),
         r"<paramPoly3> attribute pRange: expected one of arcLength, normalized, got 'p'"),
        (one_road("<line/>", 5.0, lanes=f'<laneSection s="0">{CENTRE}<left><lane id="2"/></left></laneSection>'),
         r"<left> lane ids must be 1, got \[2\]"),
        (one_road("<line/>", 5.0, lanes=f'<laneSection s="0">{CENTRE}<right><lane id="-1"><border sOffset="0" '
                  'a="1" b="0" c="0" d="0"/></lane></right></laneSection>'), r"<border> is not supported"),
        (one_road("<line/>", 5.0, lanes='<laneSection s="0" singleSide="true"><center><lane id="0"/></center>'
                  "</laneSection>"), r"<laneSection> singleSide='true' is not supported"),
        (one_road("<line/>", 5.0, lanes='<laneSection s="0"/>'), r"<laneSection> needs exactly one <center>, has 0"),
        (ROAD.replace('junction="-1">', 'junction="-1"><link><successor elementType="road" '
                  'elementId="9" contactPoint="start"/></link>'), r"<road> links to road '9', which does not exist"),
        (ROAD.replace("</OpenDRIVE>", '<junction id="1"><connection id="0" incomingRoad="r" '
                  'connectingRoad="q" contactPoint="start"/></junction></OpenDRIVE>'),
         r"<connection> names road 'q', which does not exist"),
        (ROAD.replace("</OpenDRIVE>", '<road id="r"/></OpenDRIVE>'), r"<road> has no attribute"),
        (ROAD.replace('length="5.0">', 'length="-1">'), r"<geometry> attribute length: must be >= 0"),
        # lengths are sampled: 1e12 was a MemoryError, 1e300 a ValueError, 1e6 m sampled 10 million points per border
        (ROAD.replace('length="5.0" junction', 'length="1e12" junction'),
         r"<road> attribute length: 1,000,000,000,000 exceeds the limit of 10,000,000,000 \(magnitude"),
        (ROAD.replace('length="5.0">', 'length="1e300">'), r"<geometry> attribute length: 1e\+300 exceeds the limit"),
        (ROAD.replace('length="5.0" junction', 'length="1e6" junction'),
         r"<road> attribute length: 1,000,000 m exceeds the limit of 100,000 .*VRUSIM_LIMIT_LENGTH_M raises it"),
        (ROAD.replace('length="5.0">', 'length="200000">'), r"<geometry> attribute length: 200,000 m exceeds"),
    ],
)  # fmt: skip
def test_malformed_or_unsupported_elements_are_user_errors(text, message):
    with pytest.raises(UserInputError, match=r"^test\.xodr: (line \d+: )?" + message):
        parse_xodr(text, "test.xodr")


@pytest.mark.parametrize(
    ("geometry", "element", "attribute"),
    [
        ('<arc curvature="1e308"/>', "arc", "curvature"),
        ('<spiral curvStart="0" curvEnd="1e308"/>', "spiral", "curvEnd"),
        ('<poly3 a="0" b="0" c="0" d="1e308"/>', "poly3", "d"),
        (
            '<paramPoly3 aU="0" bU="1" cU="0" dU="-1e308" aV="0" bV="0" cV="0" dV="0" pRange="arcLength"/>',
            "paramPoly3",
            "dU",
        ),
    ],
)
def test_a_huge_geometry_number_is_refused_at_its_attribute_without_warnings(tmp_path, geometry, element, attribute):
    """1e308 spilled numpy RuntimeWarnings and was reported at derived fields (road.lines[0].points)."""
    lanes = '<laneSection s="0"><center><lane id="0"/></center><right><lane id="-1" type="driving"><width sOffset="0" '
    lanes += 'a="3.5" b="0" c="0" d="1e308"/></lane></right></laneSection>'
    texts = {"geometry": one_road(geometry, 5.0), "width": one_road("<line/>", 5.0, lanes=lanes)}
    texts["x"] = one_road("<line/>", 5.0, x="-1e308")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for tag, name, text in ((element, attribute, texts["geometry"]), ("width", "d", texts["width"]),
                                ("geometry", "x", texts["x"])):  # fmt: skip
            with pytest.raises(UserInputError, match=rf"^test\.xodr: line 1: <{tag}> attribute {name}: .*XML_NUMBER"):
                parse_xodr(text, "test.xodr")


def test_the_usage_snippet_of_the_docs_runs(monkeypatch):
    """docs/opendrive_import.md's example read a junction.xodr that is not in the repository, a station beyond its
    road and a route through a road it does not have."""
    root = Path(__file__).resolve().parents[1]
    text = (root / "docs" / "opendrive_import.md").read_text()
    code = re.search(r"```python\n(from vrusim\.formats\.xodr_reader.*?)```", text, re.S)
    assert code is not None
    monkeypatch.chdir(root)
    names: dict = {}
    exec(code.group(1), names)  # the repository's own documentation
    assert names["x"].tolist() == [-50.0, -5.0] and names["route"].points[-1][1] < -40.0


def test_projecting_onto_too_long_a_network_is_refused_before_sampling(monkeypatch):
    """100 roads of 100 km took 3.3 s per projected position (a 0.5 m grid along every road), 2,000 a minute."""
    road = (
        '<road id="{i}" length="100000" junction="-1"><planView><geometry s="0" x="0" y="{i}" hdg="0" length="100000">'
        '<line/></geometry></planView><lanes><laneSection s="0"><center><lane id="0"/></center><right><lane id="-1" '
        'type="driving"><width sOffset="0" a="3.5" b="0" c="0" d="0"/></lane></right></laneSection></lanes></road>'
    )
    network = parse_xodr("<OpenDRIVE>" + "".join(road.format(i=i) for i in range(60)) + "</OpenDRIVE>", "n.xodr")
    monkeypatch.setattr("vrusim.formats.xodr_projection.nearest_station_m", lambda *args: pytest.fail("sampled"))
    with pytest.raises(UserInputError, match=r"^n\.xodr: projecting a position onto its 60 roads .*: 12,000,060 "):
        project(network, 10.0, -1.0)
