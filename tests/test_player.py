"""The scene player's data (report/player.py): frames sampled from the trace within the byte budget, their values,
the impact point, the report size of a 25 s run at dt 0.01; `vrusim view`, `vrusim compare --report` and the
notebook display (`Results._repr_html_`). The player in a browser: test_player_browser.py."""

from __future__ import annotations

import json
import math
import re

import numpy as np
import pytest
import yaml

from cli_helpers import assert_user_error, invoke
from vrusim.report.page import render
from vrusim.report.player import (
    FRAME_BUDGET_BYTES,
    MIN_FRAME_STEP_S,
    choose_stride,
    frames,
    impact_point,
    player_data,
    road_shapes,
)
from vrusim.scenario.loading import scenario_from_mapping
from vrusim.scenario.schema import Road
from vrusim.sources import scenario_of
from vrusim.viz.recording import Recording, record

CASE = "paper:pedestrian"
REPORT_LIMIT_BYTES = 2_000_000
PLAYER_DATA = re.compile(r'<script type="application/json" class="player-data">(.*?)</script>', re.S)


@pytest.fixture(scope="module")
def recordings() -> list[Recording]:
    """The pedestrian case with V2X off (impact at 5.03 s) and on (avoided, 15.67 s)."""
    return record([scenario_of(CASE, False), scenario_of(CASE, True)])


def long_scenario():
    """The pedestrian case (V2X on) on a long road: it runs the whole 25 s at dt 0.01 s."""
    data = scenario_of(CASE, True).model_dump()
    data["ego"]["route"]["length_m"] = 600.0
    data["road"]["length_m"] = 800.0
    return scenario_from_mapping(data, "long pedestrian")


def test_frames_are_every_stride_th_sample_and_the_last(recordings):
    rec = recordings[0]
    stride = 3
    f = frames(rec, stride)
    n = len(rec.t_s)
    keep = sorted({*range(0, n, stride), n - 1})
    assert f["t_s"] == pytest.approx(rec.t_s[keep].tolist())
    assert f["x_m"] == pytest.approx(rec.trace["ego_x_m"][keep].tolist(), abs=5e-4)
    assert f["y_m"] == pytest.approx(rec.trace["ego_y_m"][keep].tolist(), abs=5e-4)
    heading = np.degrees(np.arctan2(rec.trace["ego_heading_y"][keep], rec.trace["ego_heading_x"][keep]))
    assert f["heading_deg"] == pytest.approx(heading.tolist(), abs=1e-3)
    assert f["vru_x_m"][0] == pytest.approx(rec.trace["vru_x_m"][keep, 0].tolist(), abs=5e-4)
    decided = [rec.decision_index(i) for i in keep]  # what was decided at each frame's time
    assert f["vru_source"][0] == rec.trace["vru_source"][decided, 0].tolist()
    assert f["mode"] == rec.trace["planner_mode"][decided].tolist()
    assert any(f["vru_source"][0]) and len(set(f["mode"])) > 1  # the run perceives and brakes


def test_frames_are_no_closer_than_the_minimum_step(recordings):
    sampling = choose_stride(recordings)
    assert sampling.stride == round(MIN_FRAME_STEP_S / 0.01) == 2
    assert sampling.bytes <= FRAME_BUDGET_BYTES
    n = len(recordings[1].t_s)
    assert sampling.frames == len({*range(0, n, 2), n - 1})


@pytest.mark.parametrize("budget_bytes", [40_000, 20_000, 8_000])
def test_frames_fit_the_byte_budget(recordings, budget_bytes):
    data = player_data(recordings, budget_bytes=budget_bytes)
    sizes = sum(len(json.dumps(run["frames"], separators=(",", ":"))) for run in data["runs"])
    assert sizes == data["frame_bytes"] <= budget_bytes
    assert data["stride"] > 2
    full = player_data(recordings)
    assert full["frame_bytes"] > budget_bytes  # the budget did bind
    assert [run["frames"]["t_s"][-1] for run in data["runs"]] == pytest.approx([r.t_s[-1] for r in recordings])


def test_player_data_holds_the_scene(recordings):
    off, on = player_data(recordings)["runs"]
    assert (off["label"], on["label"]) == ("V2X off", "V2X on")
    assert off["rsu"] is None and on["rsu"] == {"x_m": 22.0, "y_m": 4.0, "comm_m": 41.0, "coverage_m": 20.0}
    assert off["sensor"] == {"enabled": True, "fov_deg": 120.0, "range_m": 20.0}
    assert off["ego"] == {"length_m": 4.5, "width_m": 1.8}
    assert off["vrus"][0]["type"] == "pedestrian" and off["vrus"][0]["footprint_m"] > 0
    assert on["first_v2x_message_s"] == pytest.approx(2.1)
    assert [e["name"] for e in off["events"]] == ["brake_onset", "first_perception", "impact"]
    assert off["impact"] is not None and on["impact"] is None


def test_impact_point_is_on_the_struck_footprint_facing_the_ego(recordings):
    rec = recordings[0]
    point = impact_point(rec)
    i = rec.nearest_index(point["t_s"])
    vx, vy = rec.trace["vru_x_m"][i, 0], rec.trace["vru_y_m"][i, 0]
    ex, ey = rec.trace["ego_x_m"][i], rec.trace["ego_y_m"][i]
    assert math.hypot(point["x_m"] - vx, point["y_m"] - vy) == pytest.approx(rec.scenario.vrus[0].footprint_m, abs=1e-3)
    assert math.hypot(point["x_m"] - ex, point["y_m"] - ey) < math.hypot(vx - ex, vy - ey)


def test_road_shapes_of_a_junction():
    shapes = road_shapes(Road(layout="intersection", lane_width_m=3.0, length_m=60.0))
    assert len(shapes["surfaces"]) == 2
    kinds = [line["kind"] for line in shapes["lines"]]
    assert kinds.count("edge") == 8 and kinds.count("centre") == 4 and kinds.count("stop") == 4
    straight = road_shapes(Road())
    assert [line["style"] for line in straight["lines"]] == ["solid", "solid", "broken"]


def test_report_of_a_25_s_run_stays_under_2_mb(tmp_path):
    from vrusim.report.run import run_report

    scenario = long_scenario()
    rec = record([scenario])[0]
    assert rec.t_s[-1] == pytest.approx(25.0) and scenario.sim.dt_s == 0.01
    file = tmp_path / "long.yaml"
    file.write_text(yaml.safe_dump(scenario.model_dump(mode="json", exclude_none=True)))
    text = render(run_report(file))
    size = len(text.encode("utf-8"))
    data = json.loads(PLAYER_DATA.search(text).group(1))
    assert size < REPORT_LIMIT_BYTES, size
    assert len(data["runs"][0]["frames"]["t_s"]) == 1251  # every 0.02 s, the last included
    assert data["frame_bytes"] <= FRAME_BUDGET_BYTES
    print(f"run report of a 25 s run at dt 0.01 s: {size} bytes, player frames {data['frame_bytes']} bytes")


# ----------------------------------------------------------------------------------------------- commands


def test_view_writes_the_page_without_opening_a_browser(tmp_path, monkeypatch):
    import webbrowser

    opened: list[str] = []
    monkeypatch.setattr(webbrowser, "open", lambda url: opened.append(url) or False)
    out = tmp_path / "view.html"
    result = invoke("view", CASE, "--v2x", "off,on", "--out", out, "--no-open", "--json")
    assert result.exit_code == 0, result.output
    document = json.loads(result.stdout)
    assert document == {"out": str(out), "bytes": out.stat().st_size, "opened": False}
    data = json.loads(PLAYER_DATA.search(out.read_text()).group(1))
    assert [run["label"] for run in data["runs"]] == ["V2X off", "V2X on"]
    monkeypatch.setenv("VRUSIM_NO_BROWSER", "1")
    assert invoke("view", CASE, "--v2x", "off", "--out", out).exit_code == 0
    assert opened == []
    monkeypatch.delenv("VRUSIM_NO_BROWSER")
    result = invoke("view", CASE, "--v2x", "off", "--out", out)  # no browser here: the path is printed
    assert result.exit_code == 0 and opened == [out.resolve().as_uri()]
    printed = result.stdout.replace("\n", "")  # the terminal may wrap the message anywhere
    assert str(out) in printed and "open it in a browser" in printed


def test_view_of_a_saved_trace(tmp_path):
    trace = tmp_path / "run.csv"
    assert invoke("run", CASE, "--v2x", "off", "--trace", trace).exit_code == 0
    out = tmp_path / "trace.html"
    result = invoke("view", trace, "--scenario", CASE, "--out", out, "--no-open")
    assert result.exit_code == 0, result.output
    data = json.loads(PLAYER_DATA.search(out.read_text()).group(1))
    run = data["runs"][0]
    rec = record([scenario_of(CASE, False)])[0]
    assert run["frames"]["t_s"][-1] == pytest.approx(rec.t_s[-1])
    assert run["frames"]["x_m"][-1] == pytest.approx(rec.trace["ego_x_m"][-1], abs=1e-3)
    assert run["impact"] is not None and run["impact"]["t_s"] == pytest.approx(rec.t_s[-1], abs=0.011)


@pytest.mark.parametrize(
    ("args", "names"),
    [
        (("view", CASE, "--v2x", "sometimes", "--no-open"), ("--v2x", "sometimes")),
        (("view", "run.csv", "--no-open"), ("--scenario",)),
        (("view", CASE, "--scenario", CASE, "--no-open"), ("--scenario", "saved trace")),
        (("view", CASE, "--out", "page.txt", "--no-open"), ("--out", ".html")),
        (("view", "no-such-scenario", "--no-open"), ("SOURCE",)),
        (("view", "missing.parquet", "--scenario", CASE, "--no-open"), ("SOURCE", "not found")),
        (("view", CASE, "--planner", "fsm", "--planner", "aeb", "--no-open"), ("--planner",)),
        (("compare", CASE, "--report", "out.txt"), ("--report", ".html")),
    ],
)
def test_bad_input_is_one_line_naming_the_option(args, names, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert_user_error(invoke(*args), *names)


def test_compare_report_holds_a_player_of_every_combination(tmp_path):
    out = tmp_path / "compare.html"
    result = invoke("compare", CASE, "--v2x", "off,on", "--report", out, "--json")
    assert result.exit_code == 0, result.output
    rows = json.loads(result.stdout)
    text = out.read_text()
    data = json.loads(PLAYER_DATA.search(text).group(1))
    assert [run["label"] for run in data["runs"]] == ["fsm · V2X off", "fsm · V2X on"]
    assert [run["impact"] is not None for run in data["runs"]] == [row["collisions"] == 1 for row in rows]
    assert 'id="compare-speed"' in text and 'data-group="compare"' in text


def test_notebook_shows_the_player_of_a_single_run():
    from vrusim.api import run

    single = run(CASE, v2x="off")._repr_html_()
    assert 'class="player"' in single and "vrusimPlayer" in single and "<table" in single
    data = json.loads(PLAYER_DATA.search(single).group(1))
    assert data["runs"][0]["impact"] is not None
    several = run([CASE, CASE], v2x="off")._repr_html_()
    assert 'class="player"' not in several


def test_ncap_report_adds_the_player_of_a_named_test(tmp_path):
    folder = tmp_path / "ncap"
    result = invoke("ncap", "--protocol", "2023", "--scenario", "CPNA-25", "--out", folder, "--json")
    assert result.exit_code == 0, result.output
    out = tmp_path / "ncap.html"
    test_id = "CPNA-25/20kph/day"
    result = invoke("report", folder, "--out", out, "--player", test_id)
    assert result.exit_code == 0, result.output
    text = out.read_text()
    data = json.loads(PLAYER_DATA.search(text).group(1))
    assert [run["label"] for run in data["runs"]] == [test_id] and 'id="player-cpna-25-20kph-day"' in text
    rec = record([scenario_of(f"2023:{test_id}", False)])[0]
    assert data["runs"][0]["frames"]["x_m"][-1] == pytest.approx(rec.trace["ego_x_m"][-1], abs=1e-3)
    assert_user_error(invoke("report", folder, "--out", out, "--player", "CPNA-99"), "--player", "CPNA-99")
    assert_user_error(invoke("report", CASE, "--out", out, "--player", test_id), "--player")


def test_run_writes_its_report_with_the_player(tmp_path):
    out = tmp_path / "run.html"
    result = invoke("run", CASE, "--v2x", "on", "--report", out, "--json")
    assert result.exit_code == 0, result.output
    row = json.loads(result.stdout)
    text = out.read_text()
    data = json.loads(PLAYER_DATA.search(text).group(1))
    assert data["runs"][0]["frames"]["t_s"][-1] == pytest.approx(row["end_time_s"])
    assert data["runs"][0]["rsu"] is not None and 'id="run-speed"' in text
    assert_user_error(invoke("run", CASE, "--report", tmp_path / "run.txt"), "--report", ".html")
