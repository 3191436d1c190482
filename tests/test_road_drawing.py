"""Drawn roads of imported OpenDRIVE networks (`formats.xodr_drawing`, `road.lines` / `road.surfaces`,
`viz.road_lines`): lines against hand-derived geometry, road marks, junctions, validation, the point budget, and
that figures draw them while runs and dumps of scenarios without them stay as before."""

from __future__ import annotations

import itertools
import math
import re
import shutil
from pathlib import Path

import numpy as np
import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st
from matplotlib.collections import LineCollection, PolyCollection

from vrusim.errors import UserInputError
from vrusim.formats.xodr_drawing import SIMPLIFY_TOLERANCE_M, kept_indices, road_drawing, simplified
from vrusim.formats.xodr_reader import parse_xodr, read_xodr
from vrusim.formats.xosc_import import import_xosc, read_xosc
from vrusim.paper.cases import scenario_dir
from vrusim.scenario.loading import load_scenario, scenario_from_mapping
from vrusim.scenario.schema import Road
from vrusim.scenario.settings import with_settings
from vrusim.scenario.yaml_text import scenario_yaml
from vrusim.viz.recording import record
from vrusim.viz.scene import scene_figure
from vrusim.viz.snapshots import snapshot_figure
from xosc_helpers import edited, refused

DATA = Path(__file__).parent / "data" / "xosc" / "roads"
POSITION_TOL_M = 0.02
TIME_TOL_S = 0.01


def _lines(path: str) -> list[dict]:
    return road_drawing(read_xodr(DATA / path))[0]


def _sagitta_m(points: np.ndarray, centre: tuple[float, float], radius_m: float) -> float:
    """Largest distance from the circle of any chord's midpoint (the chord error of a polyline on an arc)."""
    middles = (points[1:] + points[:-1]) / 2
    return float(np.max(np.abs(np.hypot(*(middles - centre).T) - radius_m)))


# ------------------------------------------------------------------------------------------ analytic geometry


def test_a_straight_road_draws_each_border_at_its_offset_with_its_road_mark():
    """straight.xodr (its comment derives every border): lane offset 0.5 m, two lane sections, a centre mark
    changing from broken to solid at s = 30, a curb, a sidewalk, `none` and `solid broken` marks."""
    expected = {
        ("edge", "solid", 4.0, 0.0, 50.0),
        ("edge", "solid", -3.0, 0.0, 50.0),  # driving lane | sidewalk; mark curb
        ("edge", "solid", -5.0, 0.0, 50.0),
        ("centre", "broken", 0.5, 0.0, 30.0),
        ("centre", "solid", 0.5, 30.0, 50.0),
        ("lane", "broken", -3.0, 50.0, 100.0),  # two driving lanes, no mark: broken
        ("edge", "solid", -6.5, 50.0, 100.0),  # mark "solid broken"
        ("edge", "solid", -8.5, 50.0, 100.0),
        ("centre", "solid", 0.5, 50.0, 100.0),  # no mark: solid; the left edge (mark none) is not drawn
    }
    got = set()
    for line in _lines("straight.xodr"):
        (x0, y0), (x1, y1) = line["points"]  # a straight border keeps its two ends only
        assert y0 == y1
        got.add((line["kind"], line["style"], y0, x0 + 50.0, x1 + 50.0))
    assert got == expected


def test_a_straight_road_surface_is_each_section_outline():
    _, surfaces = road_drawing(read_xodr(DATA / "straight.xodr"))
    outlines = [sorted(map(tuple, surface["points"])) for surface in surfaces]
    assert outlines == [
        sorted([(-50.0, -5.0), (0.0, -5.0), (0.0, 4.0), (-50.0, 4.0)]),
        sorted([(0.0, -8.5), (50.0, -8.5), (50.0, 4.0), (0.0, 4.0)]),
    ]


def test_an_arc_road_draws_edges_on_circles_r_minus_and_plus_the_lane_width():
    """arc.xodr: radius 50 m about (0, 50), lanes of 3.5 m: left edge radius 46.5, centre 50, right edge 53.5;
    ends at s = 0 and s = 100 (2 rad); every chord within 2 cm of its circle, points about 1.5 m or more apart."""
    centre = np.array([0.0, 50.0])
    radii = {(kind, t): 50.0 - t for kind, t in (("edge", 3.5), ("centre", 0.0), ("edge", -3.5))}
    found = []
    for line in _lines("arc.xodr"):
        points = np.array(line["points"])
        radius = float(np.hypot(*(points[0] - centre)))
        t = 50.0 - radius
        assert (line["kind"], round(t, 3)) in radii, (line["kind"], t)
        assert line["style"] == "solid"
        found.append(round(t, 3))
        assert np.hypot(*(points - centre).T) == pytest.approx(radius, abs=1e-3)  # rounded to 1 mm
        end = centre + radius * np.array([math.sin(2.0), -math.cos(2.0)])
        assert points[0] == pytest.approx([0.0, 50.0 - radius], abs=1e-3)
        assert points[-1] == pytest.approx(end, abs=1e-3)
        assert _sagitta_m(points, centre, radius) <= POSITION_TOL_M
        fewest = radius * 2.0 / math.sqrt(8 * radius * SIMPLIFY_TOLERANCE_M)  # chords of sagitta = tolerance
        assert fewest < len(points) - 1 <= 2 * fewest, (fewest, len(points))
    assert sorted(found) == [-3.5, 0.0, 3.5]


ARC_ROAD = """<OpenDRIVE><header revMajor="1" revMinor="6"/>
 <road id="1" length="{length}" junction="-1">
  <planView><geometry s="0" x="0" y="0" hdg="0" length="{length}"><arc curvature="{curvature}"/></geometry></planView>
  <lanes><laneSection s="0">
   <left><lane id="1" type="driving"><width sOffset="0" a="{width}" b="0" c="0" d="0"/></lane></left>
   <center><lane id="0" type="none"/></center>
   <right><lane id="-1" type="driving"><width sOffset="0" a="{width}" b="0" c="0" d="0"/></lane></right>
  </laneSection></lanes>
 </road>
</OpenDRIVE>"""


@settings(max_examples=25, deadline=None)
@given(
    radius=st.floats(6.0, 400.0),
    sign=st.sampled_from((-1.0, 1.0)),
    width=st.floats(1.0, 5.0),
    turn=st.floats(0.1, 3.0),
)
def test_any_arc_edge_lies_on_its_circle_within_2_cm(radius, sign, width, turn):
    """Left-, right-turning arcs of any radius and lane width: each border on the circle of radius R - sign t
    about the arc's centre, with chords within 2 cm of it."""
    text = ARC_ROAD.format(length=radius * turn, curvature=sign / radius, width=width)
    centre = np.array([0.0, sign * radius])
    radii = []
    for line in road_drawing(parse_xodr(text))[0]:
        points = np.array(line["points"])
        distance = np.hypot(*(points - centre).T)
        assert np.ptp(distance) <= 2e-3  # rounding to 1 mm
        radii.append(float(np.mean(distance)))
        assert _sagitta_m(points, centre, radii[-1]) <= POSITION_TOL_M
    assert sorted(radii) == pytest.approx(sorted(radius - sign * t for t in (width, 0.0, -width)), abs=1e-3)


@settings(max_examples=30, deadline=None)
@given(st.lists(st.tuples(st.floats(-100, 100), st.floats(-100, 100)), min_size=2, max_size=60))
def test_simplified_keeps_the_ends_and_every_dropped_point_near_its_chord(raw):
    points = np.array(raw)
    index = kept_indices(points).tolist()
    assert index[0] == 0 and index[-1] == len(points) - 1
    assert simplified(points) == pytest.approx(points[index])
    for first, last in itertools.pairwise(index):
        start, end = points[first], points[last]
        chord = end - start
        for point in points[first + 1 : last]:
            along = np.clip((point - start) @ chord / max(chord @ chord, 1e-300), 0.0, 1.0)
            assert np.hypot(*(point - start - along * chord)) <= SIMPLIFY_TOLERANCE_M + 1e-9


def test_a_junction_draws_its_connecting_roads_and_skips_marks_of_type_none():
    """junction.xodr (T junction): arms 1-3 with their edges and centre lines; connecting road 101 only its
    north kerb (y = 3.5), 102 and 103 only their kerbs, on circles of radius 1.5 m about (-5, -5) and (5, -5)."""
    lines = _lines("junction.xodr")
    assert len(lines) == 12
    inside = [np.array(line["points"]) for line in lines if all(abs(x) <= 5 and y >= -5 for x, y in line["points"])]
    assert len(inside) == 3 and all(line["kind"] == "edge" for line in lines[-3:])
    straight = [p for p in inside if len(p) == 2]
    assert [p.tolist() for p in straight] == [[[-5.0, 3.5], [5.0, 3.5]]]
    kerbs = sorted((p for p in inside if len(p) > 2), key=lambda p: p[0, 0])
    for points, centre in zip(kerbs, ([-5.0, -5.0], [5.0, -5.0]), strict=True):
        assert np.hypot(*(points - centre).T) == pytest.approx(1.5, abs=1e-3)
        assert _sagitta_m(points, centre, 1.5) <= POSITION_TOL_M
    assert {line["style"] for line in lines if line["kind"] == "centre"} == {"broken", "solid"}


# ------------------------------------------------------------------------------------------ import and run


def test_an_imported_junction_keeps_its_drawn_road_and_runs_as_derived():
    """junction.xosc, planner none: the ego at 10 m/s (x(t) - x(0) = 10 t); the pedestrian from y = -12 m,
    0 -> 2 m/s linear over 2 s from t = 1 s (y = -11.5 at 2 s, -10 at 3 s, -8 at 4 s)."""
    scenario = read_xosc(DATA / "junction.xosc")
    road = scenario.road
    assert road.layout == "intersection" and len(road.lines) == 12 and len(road.surfaces) == 6
    recording = record([with_settings(scenario, planner="none")])[0]
    trace = recording.trace
    for t_s, vru_y in ((1.0, -12.0), (2.0, -11.5), (3.0, -10.0), (4.0, -8.0)):
        index = recording.nearest_index(t_s)
        assert trace["t_s"][index] == pytest.approx(t_s, abs=TIME_TOL_S)
        assert trace["ego_x_m"][index] - trace["ego_x_m"][0] == pytest.approx(10.0 * t_s, abs=POSITION_TOL_M)
        assert trace["vru_y_m"][index, 0] == pytest.approx(vru_y, abs=POSITION_TOL_M)


def test_the_drawn_road_does_not_change_a_run():
    scenario = with_settings(read_xosc(DATA / "junction.xosc"), planner="none")
    bare = scenario.replace(**{"road.lines": None, "road.surfaces": None})
    with_road, without = record([scenario])[0].trace, record([bare])[0].trace
    assert with_road.keys() == without.keys()
    for name in with_road:
        floats = with_road[name].dtype.kind == "f"  # NaN where no V2X message is held
        assert np.array_equal(with_road[name], without[name], equal_nan=floats), name


def test_beyond_the_point_budget_the_import_keeps_the_layout_and_warns(monkeypatch):
    monkeypatch.setenv("VRUSIM_LIMIT_ROAD_POINTS", "20")
    result = import_xosc(DATA / "junction.xosc")
    assert result.scenario.road.lines is None and result.scenario.road.surfaces is None
    assert any("VRUSIM_LIMIT_ROAD_POINTS" in warning for warning in result.warnings)


def test_the_sample_count_is_checked_before_any_border_is_sampled(tmp_path, monkeypatch):
    """A 35 KB file with one 45 km road and 200 lanes a side sampled 180 million border points (2.9 GB, 39 s) before
    the point budget was checked: now the count is checked first, and the import warns naming the road."""
    lane = '<lane id="{}" type="driving"><width sOffset="0" a="3.5" b="0" c="0" d="0"/></lane>'
    folder = tmp_path / "actions"
    shutil.copytree(DATA.parent / "actions", folder)
    road = (folder / "road.xodr").read_text()
    for side, sign in (("left", 1), ("right", -1)):
        lanes = "".join(lane.format(sign * n) for n in range(1, 201))
        road = re.sub(rf"<{side}>.*</{side}>", f"<{side}>{lanes}</{side}>", road, flags=re.S)
    road = road.replace('length="200.0"', 'length="45000"')
    (folder / "road.xodr").write_text(road)
    monkeypatch.setattr("vrusim.formats.xodr_drawing._RoadSampler.sample", lambda self: pytest.fail("sampled"))
    result = import_xosc(folder / "vru_linear_time.xosc")
    assert result.scenario.road.lines is None
    (warning,) = [w for w in result.warnings if "VRUSIM_LIMIT_ROAD_SAMPLES" in w]
    assert "road.xodr: line 4: " in warning and "<road> id '1' (45000 m, 400 lanes)" in warning, warning
    assert "180,4" in warning


@pytest.mark.parametrize(
    ("old", "new", "where"),
    [
        ("<line/>", '<paramPoly3 aU="0" bU="1" cU="0" dU="1e10" aV="0" bV="0" cV="0" dV="0" pRange="arcLength"/>',
         "line 7: <geometry> of road '1': reaches"),
        ("<line/>", '<poly3 a="0" b="0" c="0" d="1e10"/>', "line 7: <geometry> of road '1': reaches"),
        ('c="-0.0" d="0.0" sOffset="0"', 'c="-0.0" d="1e10" sOffset="0"', "line 20: <lane> of road '1': its border"),
        ('x="-100.0"', 'x="-1e10"', "line 7: <geometry> of road '1': reaches (-1e+10, 0) m at s = 0 m"),
    ],
)  # fmt: skip
def test_a_road_drawn_beyond_the_coordinate_bound_names_its_element(tmp_path, old, new, where):
    """Numbers within xml_number can still place a road 10^10 m away: the message named derived fields
    (road.lines[0].points[1], road.length_m), now the geometry or lane of the .xodr."""
    folder = tmp_path / "actions"
    shutil.copytree(DATA.parent / "actions", folder)
    edited(folder / "road.xodr", old, new)
    message = refused(folder / "vru_linear_time.xosc", f"road.xodr: {where}", "VRUSIM_LIMIT_COORDINATE_M")
    assert "road.lines" not in message and "road.length_m" not in message


def test_a_road_ending_far_away_names_the_road_without_drawing(tmp_path):
    """A distribution sweep draws no road: its road.length_m (twice the farthest road end) named the road instead."""
    folder = tmp_path / "actions"
    shutil.copytree(DATA.parent / "actions", folder)
    edited(folder / "road.xodr", 'x="-100.0"', 'x="-1e9"')
    from vrusim.formats.xosc_import import parse_root, read_xosc_root

    match = r"road\.xodr: line 4: <road> id '1' ends 1e\+09 m from the origin.*VRUSIM_LIMIT_LENGTH_M"
    with pytest.raises(UserInputError, match=match):
        parse_root(*read_xosc_root(folder / "vru_linear_time.xosc"), drawing=False)


def test_the_imported_yaml_holds_the_lines_and_loads_back(tmp_path):
    folder = tmp_path / "roads"
    shutil.copytree(DATA, folder)
    from cli_helpers import invoke

    out = tmp_path / "junction.yaml"
    result = invoke("import", str(folder / "junction.xosc"), "--out", str(out))
    assert result.exit_code == 0, result.output
    text = out.read_text()
    assert "    - [-50.0, 3.5]\n    - [-5.0, 3.5]\n" in text  # one point per line
    data = yaml.safe_load(text)
    assert data["road"]["lines"][0] == {"kind": "edge", "points": [[-50.0, 3.5], [-5.0, 3.5]]}
    assert load_scenario(out).road == read_xosc(folder / "junction.xosc").road


# ------------------------------------------------------------------------------------------ reader refusals


@pytest.mark.parametrize(
    ("old", "new", "words"),
    [
        ('<roadMark sOffset="0" type="broken"/>', '<roadMark sOffset="0" type="zigzag"/>', ["<roadMark>", "type"]),
        ('<roadMark sOffset="0" type="broken"/>', '<roadMark type="broken"/>', ["<roadMark>", "'sOffset'"]),
        ('<roadMark sOffset="0" type="broken"/>', '<roadMark sOffset="x" type="broken"/>', ["<roadMark>", "sOffset"]),
    ],
)
def test_a_malformed_road_mark_is_refused_with_its_line(tmp_path, old, new, words):
    folder = tmp_path / "roads"
    shutil.copytree(DATA, folder)
    edited(folder / "junction.xodr", old, new)
    line = next(n for n, text in enumerate((folder / "junction.xodr").read_text().splitlines(), 1) if new in text)
    refused(folder / "junction.xosc", "junction.xodr", f"line {line}", *words)


def test_road_marks_out_of_order_are_refused():
    text = (DATA / "straight.xodr").read_text().replace('sOffset="30" type="solid"', 'sOffset="-1" type="solid"')
    with pytest.raises(UserInputError, match=r"line \d+: <roadMark> attribute sOffset: -1 is before"):
        parse_xodr(text, "straight.xodr")


# ------------------------------------------------------------------------------------------ the scenario field


def _mapping(**road) -> dict:
    """A bundled scenario's mapping with `road` fields."""
    data = load_scenario(sorted(scenario_dir().glob("*.yaml"))[0]).model_dump(mode="json")
    data["road"] = {"layout": "straight", **road}
    return data


@pytest.mark.parametrize(
    ("lines", "words"),
    [
        ([{"kind": "edge", "points": [[0, 0]]}], ["road.lines[0].points", "at least 2"]),
        ([{"kind": "edge", "points": [[0, 0], [".nan", 1]]}], ["road.lines[0].points"]),
        ([{"kind": "edge", "points": [[0, 0], [2e5, 1]]}], ["road.lines[0].points", "VRUSIM_LIMIT_COORDINATE_M"]),
        ([{"kind": "kerb", "points": [[0, 0], [1, 1]]}], ["road.lines[0].kind"]),
        ([{"kind": "edge", "style": "dotted", "points": [[0, 0], [1, 1]]}], ["road.lines[0].style"]),
        ([{"kind": "edge", "points": [[0, 0, 0], [1, 1]]}], ["road.lines[0].points[0]"]),
    ],
)
def test_a_bad_road_line_is_refused_naming_its_field(lines, words):
    data = _mapping(lines=lines)
    if lines[0]["points"][-1][0] == ".nan":
        data["road"]["lines"][0]["points"][1][0] = float("nan")
    with pytest.raises(UserInputError) as caught:
        scenario_from_mapping(data, "case.yaml")
    for word in words:
        assert word in str(caught.value), (word, str(caught.value))


def test_the_point_budget_is_checked_on_the_scenario(monkeypatch):
    monkeypatch.setenv("VRUSIM_LIMIT_ROAD_POINTS", "4")
    data = _mapping(
        lines=[{"kind": "edge", "points": [[0, 0], [1, 0], [2, 0]]}], surfaces=[{"points": [[0, 0], [1, 0], [1, 1]]}]
    )
    with pytest.raises(UserInputError, match=r"6 points exceeds the limit of 4 .*VRUSIM_LIMIT_ROAD_POINTS"):
        scenario_from_mapping(data, "case.yaml")


def test_a_scenario_without_a_drawn_road_dumps_as_before():
    """No `lines` / `surfaces` keys in any dump (so sweep digests and reports of such scenarios do not change)."""
    assert Road().model_dump() == {"layout": "straight", "lane_width_m": 3.5, "length_m": 200.0}
    for path in sorted(scenario_dir().glob("*.yaml")):
        scenario = load_scenario(path)
        for dump in (scenario.model_dump(), scenario.model_dump(mode="json")):
            assert set(dump["road"]) == {"layout", "lane_width_m", "length_m"}, path
        assert '"lines"' not in scenario.model_dump_json()
        data = scenario.model_dump(mode="json")
        assert scenario_yaml(data) == yaml.safe_dump(data, sort_keys=False, allow_unicode=True)


# ------------------------------------------------------------------------------------------ figures


def _drawn(ax) -> tuple[list, list]:
    """(line point lists, surface outlines) the axes' road collections carry."""
    lines = [seg.tolist() for c in ax.collections if isinstance(c, LineCollection) for seg in c.get_segments()]
    surfaces = [
        p.vertices[:-1].tolist() if p.codes is not None else p.vertices.tolist()
        for c in ax.collections
        if isinstance(c, PolyCollection)
        for p in c.get_paths()
    ]
    return lines, surfaces


def test_a_figure_of_an_imported_junction_draws_its_lines_not_the_layout():
    scenario = with_settings(read_xosc(DATA / "junction.xosc"), planner="none")
    recording = record([scenario])[0]
    fig = scene_figure(recording, 2.0)
    fig.canvas.draw()  # renders (Agg)
    ax = fig.axes[0]
    lines, surfaces = _drawn(ax)
    assert sorted(lines) == sorted([list(map(list, line.points)) for line in scenario.road.lines])
    assert len(surfaces) == len(scenario.road.surfaces)
    for got, surface in zip(surfaces, scenario.road.surfaces, strict=True):
        assert np.array(got)[: len(surface.points)] == pytest.approx(np.array(surface.points))
    assert not [p for p in ax.patches if type(p).__name__ == "Rectangle"]  # the layout's road is not drawn
    snapshot_figure([recording]).canvas.draw()


def test_a_figure_of_a_scenario_without_lines_draws_the_layout():
    scenario = load_scenario(sorted(scenario_dir().glob("*.yaml"))[0])
    fig = scene_figure(record([scenario])[0], 1.0)
    lines, surfaces = _drawn(fig.axes[0])
    assert lines == [] and surfaces == []
    assert [p for p in fig.axes[0].patches if type(p).__name__ == "Rectangle"]


# ------------------------------------------------------------------------------------------ export and sweeps


def test_the_export_writes_the_layouts_road_and_notes_the_drawn_one(tmp_path):
    pytest.importorskip("scenariogeneration")
    from vrusim.interop.openscenario import DRAWN_ROAD_NOTE, export_openscenario

    scenario = read_xosc(DATA / "junction.xosc")
    export_openscenario(scenario, tmp_path, "drawn")
    export_openscenario(scenario.replace(**{"road.lines": None, "road.surfaces": None}), tmp_path, "bare")
    undated = [re.sub(r'date="[^"]*"', "", (tmp_path / f"{stem}.xodr").read_text()) for stem in ("drawn", "bare")]
    assert undated[0] == undated[1]
    assert DRAWN_ROAD_NOTE in (tmp_path / "drawn.xosc").read_text()
    assert "vrusim_road" not in (tmp_path / "bare.xosc").read_text()


def test_a_distribution_sweep_keeps_no_drawn_road():
    from vrusim.sweep.xosc_sweep import distribution_sweep

    plan = distribution_sweep(Path(__file__).parent / "data" / "xosc" / "distribution" / "cpna_10x3.xosc").plan
    assert all(set(base["road"]) == {"layout", "lane_width_m", "length_m"} for base in plan.bases.values())


def test_gym_frames_draw_the_drawn_road():
    pytest.importorskip("gymnasium")
    from vrusim.gym.env import VruEnv

    scenario = read_xosc(DATA / "junction.xosc")
    frames = []
    for case in (scenario, scenario.replace(**{"road.lines": None, "road.surfaces": None})):
        env = VruEnv(case, render_mode="rgb_array")
        env.reset(seed=0)
        frames.append(env.render())
    assert frames[0].shape == frames[1].shape and not np.array_equal(frames[0], frames[1])
