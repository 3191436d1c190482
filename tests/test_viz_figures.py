"""Recordings, scene, snapshot and time-series figures: pixels where they must be, panels and titles as the key
events say, and the figure options of `vrusim run` / `vrusim paper` with their error cases."""

from __future__ import annotations

import dataclasses
import math
import warnings

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.colors import to_rgb
from matplotlib.figure import Figure
from matplotlib.text import Text
from PIL import Image

from cli_helpers import assert_user_error, invoke
from conftest import PAPER_DIR
from vrusim.paper.cases import paper_scenarios
from vrusim.report.figures import png_bytes
from vrusim.viz import style
from vrusim.viz.figure_io import write_figure
from vrusim.viz.recording import KEY_EVENT_LABELS, record
from vrusim.viz.runplot import run_figure
from vrusim.viz.scene import SceneArtists, ViewWindow, scene_figure
from vrusim.viz.snapshots import snapshot_figure
from vrusim.viz.timeseries import mode_spans, timeseries_figure

PEDESTRIAN = PAPER_DIR / "pedestrian_crossing.yaml"


@pytest.fixture(scope="module")
def pedestrian():
    """The paper's pedestrian case, V2X off and on (one traced batch)."""
    scenarios = [s for case, _, s in paper_scenarios() if case.key == "pedestrian"]
    return record(scenarios)


def _pixel(fig: Figure, ax, x_m: float, y_m: float) -> np.ndarray:
    """RGB (0..255) of the rendered pixel at world point (x_m, y_m)."""
    image = np.asarray(fig.canvas.buffer_rgba())[:, :, :3].astype(int)
    px, py = ax.transData.transform((x_m, y_m))
    return image[image.shape[0] - 1 - round(float(py)), round(float(px))]


def _close(pixel: np.ndarray, colour: str, tol: int = 8) -> bool:
    return bool(np.all(np.abs(pixel - np.array(to_rgb(colour)) * 255) <= tol))


# ----------------------------------------------------------------------------------------------- recording


def test_first_row_is_the_scenario_start(pedestrian):
    for rec in pedestrian:
        start, trace = rec.scenario.ego.start, rec.trace
        assert rec.t_s[0] == 0.0
        assert trace["ego_x_m"][0] == pytest.approx(start.x_m)
        assert trace["ego_y_m"][0] == pytest.approx(start.y_m)
        heading = math.radians(start.heading_deg)
        assert trace["ego_heading_x"][0] == pytest.approx(math.cos(heading))
        assert trace["ego_heading_y"][0] == pytest.approx(math.sin(heading))
        assert trace["ego_speed_mps"][0] == pytest.approx(rec.scenario.ego.start_speed_mps)
        vru = rec.scenario.vrus[0]
        assert (trace["vru_x_m"][0, 0], trace["vru_y_m"][0, 0]) == pytest.approx((vru.start.x_m, vru.start.y_m))
        assert np.all(np.diff(rec.t_s) > 0)


def test_key_events_agree_with_the_summary_row(pedestrian):
    off, on = pedestrian
    for rec in pedestrian:
        row = rec.summary
        seen = [t for t in (row["first_sensor_detection_s"], row["first_v2x_message_s"]) if t is not None]
        assert rec.events_s["first_perception"] == pytest.approx(min(seen))
        assert rec.t_s[-1] == pytest.approx(row["end_time_s"])
        t, command = rec.decisions("ego_command_mps2")
        first_brake = t[np.flatnonzero(command < 0)[0]]
        assert rec.events_s["brake_onset"] == pytest.approx(first_brake)
        assert np.all(command[t < first_brake - 1e-9] >= 0)
    assert off.events_s["impact"] == pytest.approx(off.summary["contact_time_s"])
    assert "closest_approach" not in off.events_s
    assert "impact" not in on.events_s
    assert on.trace["clearance_m"][on.nearest_index(on.events_s["closest_approach"])] == pytest.approx(
        on.summary["min_clearance_m"], abs=1e-6
    )


def test_key_moments_merge_events_at_the_same_time(pedestrian):
    off = pedestrian[0]
    moments = off.key_moments()
    assert moments[0] == ("start", 0.0)
    assert [t for _, t in moments] == sorted(t for _, t in moments)
    labels = " + ".join(label for label, _ in moments)
    for name in off.events_s:
        assert KEY_EVENT_LABELS[name] in labels
    # the paper's pedestrian run perceives and brakes in the same step: one moment
    assert off.events_s["first_perception"] == off.events_s["brake_onset"]
    assert moments[1][0] == "first perception + brake onset"


# ----------------------------------------------------------------------------------------------- scene pixels


def _scene(rec, t_s: float, box=(-50.0, 10.0, -18.0, 18.0)):
    """The scene at a fixed 10 px per metre over `box` (x_min, x_max, y_min, y_max), axes filling the figure."""
    fig = Figure(figsize=((box[1] - box[0]) / 10, (box[3] - box[2]) / 10), dpi=100)
    FigureCanvasAgg(fig)
    ax = fig.add_axes((0, 0, 1, 1))
    window = ViewWindow(box, box[1] - box[0], box[3] - box[2], follow=False)
    scene = SceneArtists(ax, rec, window, label=False)
    index = rec.index_at(t_s)
    scene.update(index)
    fig.canvas.draw()
    return fig, ax, index


def test_sensor_sector_is_blue_inside_and_absent_outside(pedestrian):
    rec = pedestrian[0]  # V2X off: no RSU range tint
    fig, ax, i = _scene(rec, 1.0)
    trace, ego, sensor = rec.trace, rec.scenario.ego, rec.scenario.sensor
    hx, hy = trace["ego_heading_x"][i], trace["ego_heading_y"][i]
    apex = np.array([trace["ego_x_m"][i] + hx * ego.length_m / 2, trace["ego_y_m"][i] + hy * ego.length_m / 2])
    heading = math.atan2(hy, hx)

    def at(angle_deg: float, distance_m: float) -> np.ndarray:
        a = heading + math.radians(angle_deg)
        return _pixel(fig, ax, *(apex + distance_m * np.array([math.cos(a), math.sin(a)])))

    def blue(p: np.ndarray) -> bool:
        return p[2] - p[0] > 25

    half = sensor.fov_deg / 2
    for angle, frac in ((30, 0.7), (-30, 0.7), (half - 8, 0.5), (0.5 * half, 0.95)):
        assert blue(at(angle, frac * sensor.range_m)), (angle, frac)
    for angle, frac in ((half + 12, 0.7), (-(half + 12), 0.7), (30, 1.25), (150, 0.3)):  # last: behind, on the road
        pixel = at(angle, frac * sensor.range_m)
        assert not blue(pixel), (angle, frac, pixel)
    ground = at(half + 12, 0.7 * sensor.range_m)
    assert _close(ground, style.GROUND)


def test_sensor_sector_is_cut_where_an_obstacle_hides_the_view(scenario_dict):
    """A parked car ahead-left casts a shadow: the blue stops at the car and resumes beside its shadow."""
    from vrusim.scenario.loading import scenario_from_mapping

    scenario_dict["obstacles"] = [
        {"centre": {"x_m": 10.0, "y_m": 3.0, "heading_deg": 0.0}, "length_m": 4.0, "width_m": 2.0}
    ]
    rec = record([scenario_from_mapping(scenario_dict)])[0]
    fig, ax, _ = _scene(rec, 0.0, box=(-10.0, 30.0, -20.0, 20.0))
    apex = np.array([2.25, 0.0])  # front bumper of the 4.5 m ego centred at the origin

    def blue(x: float, y: float) -> bool:
        p = _pixel(fig, ax, x, y)
        return p[2] - p[0] > 25

    def along(angle_deg: float, distance_m: float) -> tuple[float, float]:
        a = math.radians(angle_deg)
        return tuple(apex + distance_m * np.array([math.cos(a), math.sin(a)]))

    to_car = math.degrees(math.atan2(3.0, 10.0 - 2.25))  # 21.2°: straight at the car's centre
    assert blue(*along(to_car, 5.0))  # between the bumper and the car
    assert not blue(*along(to_car, 14.0)) and not blue(*along(to_car, 18.0))  # in its shadow
    assert blue(*along(-to_car, 14.0)) and blue(*along(-to_car, 18.0))  # the mirror direction is clear
    assert blue(*along(45.0, 14.0))  # past the shadow's far edge (the car spans 12°–35° from the apex)


def test_ego_rectangle_and_vru_circle_at_their_positions(pedestrian):
    rec = pedestrian[0]
    fig, ax, i = _scene(rec, 1.0, box=(-40.0, 25.0, -15.0, 10.0))
    trace = rec.trace
    assert _close(_pixel(fig, ax, trace["ego_x_m"][i], trace["ego_y_m"][i]), style.EGO_FACE)
    behind = trace["ego_x_m"][i] - rec.scenario.ego.length_m / 2 - 1.5
    assert not _close(_pixel(fig, ax, behind, trace["ego_y_m"][i] + 2.0), style.EGO_FACE, tol=40)
    vx, vy = trace["vru_x_m"][i, 0], trace["vru_y_m"][i, 0]
    assert _close(_pixel(fig, ax, vx, vy), style.vru_colour("pedestrian"))
    assert not _close(_pixel(fig, ax, vx + 2.0, vy), style.vru_colour("pedestrian"), tol=40)


def test_detection_ring_shows_only_once_perceived(pedestrian):
    rec = pedestrian[0]
    seen_at = rec.events_s["first_perception"]
    _fig, ax, _ = _scene(rec, seen_at - 0.5)
    ring = SceneArtists(ax, rec, label=False)
    ring.update(rec.nearest_index(seen_at - 0.5))
    assert not ring.sensor_rings[0].get_visible()
    ring.update(rec.nearest_index(seen_at))
    assert ring.sensor_rings[0].get_visible()
    assert not ring.v2x_rings[0].get_visible()
    on = pedestrian[1]
    ring_on = SceneArtists(ax, on, label=False)
    ring_on.update(on.nearest_index(on.events_s["first_perception"]))
    assert ring_on.v2x_rings[0].get_visible()


# ----------------------------------------------------------------------------------------------- snapshots


def test_snapshot_panels_are_the_key_moments(pedestrian):
    fig = snapshot_figure(pedestrian, dpi=40)
    shown = [ax for ax in fig.axes if ax.get_visible()]
    expected = [m for rec in pedestrian for m in rec.key_moments()]
    assert len(shown) == len(expected)
    for ax, (label, t) in zip(shown, expected, strict=True):
        title = ax.get_title(loc="left")
        assert label in title and f"t = {t:.2f} s" in title
    assert "V2X off: collision" in shown[0].get_ylabel()
    fig.canvas.draw()


def test_snapshot_at_chosen_times(pedestrian):
    fig = snapshot_figure(pedestrian, at_s=[1.0, 2.5, 4.0], dpi=40)
    shown = [ax for ax in fig.axes if ax.get_visible()]
    assert len(shown) == 6
    titles = [ax.get_title(loc="left") for ax in shown]
    assert titles[:3] == ["(a) t = 1.00 s", "(b) t = 2.50 s", "(c) t = 4.00 s"]
    assert titles[3].startswith("(d) t = 1.00 s")


# ----------------------------------------------------------------------------------------------- time series


def test_time_series_band_colours_follow_the_planner_mode(pedestrian):
    fig = timeseries_figure(pedestrian, dpi=60)
    fig.canvas.draw()
    band = fig.axes[3]
    checked = 0
    for row, rec in enumerate(pedestrian):
        y = len(pedestrian) - 1 - row
        for start, stop, mode in mode_spans(rec):
            if stop - start < 0.3:
                continue
            t = (start + stop) / 2
            if any(abs(t - e) < 0.2 for e in rec.events_s.values()):
                t = start + 0.25 * (stop - start)
            assert _close(_pixel(fig, band, t, y), style.mode_colour(rec.mode_names[mode])), (row, t)
            checked += 1
    assert checked >= 4
    assert [t.get_text() for t in band.get_yticklabels()] == ["V2X on", "V2X off"]


def test_time_series_shows_every_key_event(pedestrian):
    fig = timeseries_figure(pedestrian, dpi=40)
    speed = fig.axes[0]
    vertical = [ln.get_xdata()[0] for ln in speed.get_lines() if len(set(ln.get_xdata())) == 1]
    for rec in pedestrian:
        for t in rec.events_s.values():
            assert any(abs(x - t) < 1e-9 for x in vertical), t


# ----------------------------------------------------------------------------------------------- CLI


def _leftovers(folder) -> list[str]:
    return [p.name for p in folder.iterdir()]


def test_run_plot_writes_one_figure(tmp_path):
    out = tmp_path / "run.png"
    result = invoke("run", PEDESTRIAN, "--plot", out)
    assert result.exit_code == 0, result.output
    assert "Figure written" in result.output
    with Image.open(out) as image:
        assert image.format == "PNG" and image.width > 800 and image.height > 800
    assert _leftovers(tmp_path) == ["run.png"]
    svg = tmp_path / "run.svg"
    assert invoke("run", PEDESTRIAN, "--plot", svg, "--json").exit_code == 0
    assert svg.read_text().lstrip().startswith("<?xml")


@pytest.mark.parametrize(
    ("option", "name", "message"),
    [
        ("--plot", "run.txt", "unknown figure type"),
        ("--plot", "missing/run.png", "does not exist"),
        ("--animate", "run.avi", "unknown animation type"),
        ("--animate", "missing/run.gif", "does not exist"),
    ],
)
def test_run_figure_options_reject_bad_paths(tmp_path, option, name, message):
    result = invoke("run", PEDESTRIAN, option, tmp_path / name)
    assert_user_error(result, option, message)
    assert _leftovers(tmp_path) == []


def test_run_plot_into_a_folder_is_a_user_error(tmp_path):
    (tmp_path / "dir.png").mkdir()
    assert_user_error(invoke("run", PEDESTRIAN, "--plot", tmp_path / "dir.png"), "--plot", "folder")


def test_paper_figures_writes_six_pngs(tmp_path):
    out = tmp_path / "figs"
    result = invoke("paper", "--figures", out)
    assert result.exit_code == 0, result.output
    names = sorted(p.name for p in out.iterdir())
    assert names == sorted(
        f"{case}_{kind}.png"
        for case in ("pedestrian", "escooter", "motorcyclist")
        for kind in ("snapshots", "timeseries")
    )
    for path in out.iterdir():
        with Image.open(path) as image:
            assert image.width > 600


def test_paper_figures_rejects_a_file_or_missing_parent(tmp_path):
    afile = tmp_path / "file.txt"
    afile.write_text("x")
    assert_user_error(invoke("paper", "--figures", afile), "--figures", "not a folder")
    assert_user_error(invoke("paper", "--figures", tmp_path / "a" / "b"), "--figures", "does not exist")
    assert _leftovers(tmp_path) == ["file.txt"]


@given(
    apex=st.tuples(st.floats(-20, 20), st.floats(-20, 20)),
    centre=st.tuples(st.floats(-10, 10), st.floats(-10, 10)),
    heading_deg=st.floats(-180, 180),
    size=st.tuples(st.floats(0.5, 6.0), st.floats(0.5, 3.0)),
    ray_deg=st.floats(-180, 180),
)
def test_ray_box_distance_matches_marching_along_the_ray(apex, centre, heading_deg, size, ray_deg):
    """The slab test behind the drawn sensor shadow against stepping along the ray in 1 cm steps."""
    from vrusim.viz.scene import _ray_box_distances

    h = math.radians(heading_deg)
    box = np.array([*centre, math.cos(h), math.sin(h), size[0] / 2, size[1] / 2])
    direction = np.array([[math.cos(math.radians(ray_deg)), math.sin(math.radians(ray_deg))]])
    got = float(_ray_box_distances(np.array(apex), direction, box)[0])
    steps = np.arange(0.0, 60.0, 0.01)
    points = np.array(apex) + steps[:, None] * direction[0]
    local_x = (points[:, 0] - centre[0]) * box[2] + (points[:, 1] - centre[1]) * box[3]
    local_y = (points[:, 1] - centre[1]) * box[2] - (points[:, 0] - centre[0]) * box[3]
    inside = (np.abs(local_x) <= box[4]) & (np.abs(local_y) <= box[5])
    if inside.any():  # the first sample inside lies less than one step past the entry
        assert got <= steps[np.argmax(inside)] + 1e-9 <= got + 0.01 + 1e-9
    elif got != math.inf:  # a graze the 1 cm steps stepped over: the entry point is on the box's outline
        hit = np.array(apex) + got * direction[0]
        lx = (hit[0] - centre[0]) * box[2] + (hit[1] - centre[1]) * box[3]
        ly = (hit[1] - centre[1]) * box[2] - (hit[0] - centre[0]) * box[3]
        assert abs(lx) <= box[4] + 1e-6 and abs(ly) <= box[5] + 1e-6


# ----------------------------------------------------------------------------------------------- user text


@pytest.mark.parametrize("name", ["A$$B", "a $x^$ b", "$_$", "$x$ 🚗"])
def test_user_text_is_drawn_literally_and_quietly(pedestrian, tmp_path, name):
    """A `$` in a scenario name or description is a dollar sign (no mathtext, which failed to parse `A$$B`); a
    character the font lacks is drawn without a warning on stderr."""
    scenario = pedestrian[0].scenario.replace(name=name, description=f"text {name}")
    rec = dataclasses.replace(pedestrian[0], scenario=scenario)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        fig = run_figure([rec], dpi=40.0)
        write_figure(fig, tmp_path / "run.png", dpi=40.0)
        assert png_bytes(scene_figure(rec, 0.0, width_in=4.0, dpi=40.0), dpi=40.0).startswith(b"\x89PNG")
    assert any(name in t.get_text() for t in fig.findobj(Text))
    assert not any(t.get_parse_math() for t in fig.findobj(Text))
