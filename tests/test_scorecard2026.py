"""The 2026 scorecard (PNG, terminal) and report: what they show equals the assessment, laid out as FC26 prints it."""

from __future__ import annotations

import json
from html.parser import HTMLParser
from io import StringIO

import pyarrow as pa
import pyarrow.parquet as pq
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from matplotlib.colors import to_rgba
from rich.console import Console

from report_helpers import read_report
from vrusim.errors import UserInputError
from vrusim.ncap.rating2026 import assess_2026
from vrusim.ncap.rating2026.colours import KPH
from vrusim.ncap.results2026 import (
    VERIFICATION_FILE,
    read_verification,
    result_rows_2026,
    verification_from_dict,
    write_verification,
)
from vrusim.ncap.verification import monte_carlo
from vrusim.report.ncap2026 import ncap_2026_report
from vrusim.report.page import RESULTS_ID, render
from vrusim.report.sources import build_report
from vrusim.viz.ncap_colours import COLOUR_HEX
from vrusim.viz.scorecard2026 import EXTENDED_SUFFIX, scorecard_2026_figure, write_scorecard_2026_png
from vrusim.viz.scorecard2026_terminal import grid_table, scorecard_2026_renderables, sub_element_grids

SPEEDS = (10, 20, 30, 40, 50, 60)
LOCATIONS = (0.9, 0.75, 0.5, 0.25, 0.1)
"""CPNA day grid (FC26 §3): VUT 10-60 km/h × 90/75/50/25/10 %; 75/50/25 % standard, 90/10 % extended (R26)."""
ROWS_SHOWN = ("10 km/h", "20 km/h", "30 km/h", "40 km/h", "50 km/h", "60 km/h")
COLUMNS_SHOWN = ("90%", "75%", "50%", "25%", "10%")
"""The grid as FC26 prints it: speed ascending downwards, impact location 100 % first (left)."""
VRELS = (None, 3.0, 8.0, 15.0, 25.0, 45.0)


def cpna(vrel_at, skip=()) -> list[dict]:
    rows = []
    for vut in SPEEDS:
        for loc in LOCATIONS:
            if (vut, loc) in skip:
                continue
            vrel = vrel_at(vut, loc)
            rows.append({
                "test_id": f"CPNA/{vut}/{loc}", "protocol": "2026", "scenario": "CPNA", "official_scenario": "CPNA day",
                "lighting": "day", "vut_speed_kph": float(vut), "impact_location": loc, "target_speed_kph": 5.0,
                "range": "standard" if loc in (0.75, 0.5, 0.25) else "extended", "function": "AEB",
                "collided": vrel is not None, "impact_speed_mps": None if vrel is None else vrel * KPH,
                "target_longitudinal_speed_mps": 0.0, "warning_ttc_s": None, "planner_warns": False,
                "planner": "aeb", "v2x": False,
            })  # fmt: skip
    return rows


def cmftap(crash=()) -> list[dict]:
    """CMFtap (FC26 §3.1.1.5): VUT turning 10/15/20/25 km/h × EMT 30/45/60/80 km/h, avoidance only."""
    rows = []
    for vut in (10, 15, 20, 25):
        for emt in (30, 45, 60, 80):
            hit = (vut, emt) in crash
            rows.append({
                "test_id": f"CMFtap/{vut}/{emt}", "protocol": "2026", "scenario": "CMFtap",
                "official_scenario": "CMFtap", "lighting": "day", "vut_speed_kph": float(vut), "impact_location": 0.5,
                "target_speed_kph": float(emt), "range": "extended" if emt == 80 or vut == 25 else "standard",
                "function": "avoidance", "collided": hit, "impact_speed_mps": 5.0 if hit else None,
                "target_longitudinal_speed_mps": None, "warning_ttc_s": None, "planner_warns": False,
                "planner": "aeb", "v2x": False,
            })  # fmt: skip
    return rows


def nominal(assessment, flip=()):
    """A lab simulator that reproduces each cell's KPI, except tests in `flip`, which crash at 45 km/h."""
    cells = {c.test_id: c for c in assessment.cells}

    def simulate(runs):
        out = []
        for run in runs:
            kpi = 45.0 if run.test_id in flip else cells[run.test_id].kpi
            out.append(
                {"collided": bool(kpi), "impact_speed_mps": (kpi or 0) * KPH, "target_longitudinal_speed_mps": 0}
            )
        return out

    return simulate


def patches_by_gid(fig) -> dict[str, object]:
    return {p.get_gid(): p for sub in fig.subfigs for ax in sub.axes for p in ax.patches if p.get_gid()}


# ----------------------------------------------------------------------------------------------- PNG

vrel_grid = st.lists(st.sampled_from(VRELS), min_size=30, max_size=30)


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(vrels=vrel_grid)
def test_figure_cells_carry_the_assessed_colours_at_the_protocol_positions(vrels):
    table = dict(zip([(v, loc) for v in SPEEDS for loc in LOCATIONS], vrels, strict=True))
    a = assess_2026(cpna(lambda v, loc: table[(v, loc)], skip={(10, 0.9)}))
    patches = patches_by_gid(scorecard_2026_figure(a, dpi=40))
    for c in a.cells:
        patch = patches[c.test_id]
        assert patch.get_facecolor() == pytest.approx(to_rgba(COLOUR_HEX[c.colour]))
        i, j = ROWS_SHOWN.index(f"{c.vut_speed_kph:g} km/h"), COLUMNS_SHOWN.index(f"{round(c.impact_location * 100)}%")
        assert patch.get_xy() == pytest.approx((j - 0.5, i - 0.5))
        hatch = patches.get(c.test_id + EXTENDED_SUFFIX)
        assert (hatch is not None and bool(hatch.get_hatch())) == (c.range == "extended")
    grey = patches["untested:10 km/h|90%"]
    assert grey.get_facecolor() == pytest.approx(to_rgba(COLOUR_HEX["untested"]))
    assert grey.get_xy() == pytest.approx((-0.5, -0.5))


def test_figure_colours_by_hand_and_titles_with_points():
    # 60 km/h, 50 %: Vrel 15 km/h -> orange (FC26 §5.2: 10 < v <= 20 at >= 50 km/h); 30 km/h, 25 %: 8 -> brown
    a = assess_2026(cpna(lambda v, loc: {(60, 0.5): 15.0, (30, 0.25): 8.0}.get((v, loc))) + cmftap({(25, 80)}))
    fig = scorecard_2026_figure(a, dpi=40)
    patches = patches_by_gid(fig)
    assert patches["CPNA/60/0.5"].get_facecolor() == pytest.approx(to_rgba(COLOUR_HEX["orange"]))
    assert patches["CPNA/60/0.5"].get_xy() == pytest.approx((2 - 0.5, 5 - 0.5))
    assert patches["CPNA/30/0.25"].get_facecolor() == pytest.approx(to_rgba(COLOUR_HEX["brown"]))
    # CMFtap columns are target speeds ascending (FC26 §3.1.1.5): 80 km/h is the 4th column, 25 km/h the 4th row
    assert patches["CMFtap/25/80"].get_xy() == pytest.approx((3 - 0.5, 3 - 0.5))
    assert patches["CMFtap/25/80"].get_facecolor() == pytest.approx(to_rgba(COLOUR_HEX["red"]))
    # CPNA day standard cells (75/50/25 % × 6 speeds = 18): 16 green, 1 orange, 1 brown; extended all green
    std = (16 * 1.0 + 0.5 + 0.25) / 18 * 0.5
    assert a.scenarios["CPNA day"].standard == pytest.approx(std)
    titles = [ax.get_title(loc="left") for sub in fig.subfigs for ax in sub.axes]
    assert f"CPNA day: {std + 0.0625:.2f} / 0.6875" in titles  # max 0.5 + 0.0625 + 0.125 (FC26 §3 CPNA)
    assert f"CMFtap: {a.scenarios['CMFtap'].total:.2f} / 5" in titles  # 4 + 0.5 + 0.5
    title = fig._suptitle.get_text()
    assert f"FC Pedestrian & Cyclist {std + 0.0625:.2f} / 20" in title
    assert f"FC Car & PTW (motorcyclist part) {a.scenarios['CMFtap'].total:.2f} / 16" in title


def test_png_is_written(tmp_path):
    a = assess_2026(cpna(lambda v, loc: None))
    path = write_scorecard_2026_png(a, tmp_path / "scorecard.png", dpi=40)
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


# ----------------------------------------------------------------------------------------------- Rich


def natural_width(renderable) -> int:
    console = Console(width=10_000)
    return console.measure(renderable).maximum


def test_terminal_grids_fit_80_columns_and_name_every_scenario():
    a = assess_2026(cpna(lambda v, loc: 15.0 if v == 60 else None) + cmftap({(25, 80)}))
    renderables = scorecard_2026_renderables(a)
    for renderable in renderables[:-1]:  # the grids and the key; the points table is fitted by the CLI
        assert natural_width(renderable) <= 80
    console = Console(width=80, file=StringIO(), record=True, color_system="truecolor")
    for renderable in renderables:
        console.print(renderable)
    text = console.export_text(clear=False)
    assert all(len(line) <= 80 for line in text.splitlines())
    for name, points in a.scenarios.items():
        assert f"{name} {points.total:.2f}/" in text  # grid title
        assert f"{points.total:.2f}" in text
    assert "FC Pedestrian & Cyclist: " in text and "FC Car & PTW (motorcyclist part): " in text
    html = console.export_html(inline_styles=True)
    assert COLOUR_HEX["orange"] in html and COLOUR_HEX["red"] in html  # coloured blocks


def test_terminal_grid_has_one_block_per_cell_extended_marked():
    a = assess_2026(cpna(lambda v, loc: None, skip={(10, 0.9)}))
    console = Console(width=80, file=StringIO(), record=True)
    console.print(grid_table(a, "CPNA day"))
    lines = console.export_text().splitlines()
    assert lines[1].split() == ["IL%", "90", "75", "50", "25", "10"]
    assert lines[2].split() == ["10", "·", "e"]  # 90 % untested, 75/50/25 standard (blank), 10 % extended
    assert lines[3].split() == ["20", "e", "e"]
    assert natural_width(sub_element_grids(a, "FC Pedestrian & Cyclist", ["CPNA day", "CPNA day"])) <= 80


def test_terminal_verification_table_shows_the_spread():
    a = assess_2026(cpna(lambda v, loc: None))
    v = monte_carlo(a, nominal(a, flip={"CPNA/30/0.5"}), n_draws=200, n_perturbations=2)
    console = Console(width=120, file=StringIO(), record=True)
    for renderable in scorecard_2026_renderables(a, v):
        console.print(renderable)
    text = console.export_text()
    s = v.scenarios["CPNA day"]
    assert s.std > 0  # the flipped cell fails whenever it is drawn
    assert f"{s.mean:.2f} ± {s.std:.2f}" in text and f"{s.p5:.2f}–{s.p95:.2f}" in text
    e = v.sub_elements["FC Pedestrian & Cyclist"]
    assert f"{e.mean:.2f} ± {e.std:.2f}" in text


# ----------------------------------------------------------------------------------------------- HTML


class GridReader(HTMLParser):
    """The `<td>` attributes and text of every 2026 grid table, by table id."""

    def __init__(self) -> None:
        super().__init__(convert_charrefs=True)
        self.grids: dict[str, list[dict]] = {}
        self._grid: str | None = None
        self._td: dict | None = None

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag == "table" and a.get("class") == "grid":
            self._grid = a["id"]
            self.grids[self._grid] = []
        elif tag == "td" and self._grid:
            self._td = {**a, "text": ""}
            self.grids[self._grid].append(self._td)

    def handle_endtag(self, tag):
        if tag == "table":
            self._grid = None
        if tag == "td":
            self._td = None

    def handle_data(self, data):
        if self._td is not None:
            self._td["text"] += data


def grids_of(html: str) -> dict[str, list[dict]]:
    reader = GridReader()
    reader.feed(html)
    return reader.grids


def test_html_grid_has_one_cell_per_test_with_colour_and_pass_probability():
    rows = cpna(lambda v, loc: 15.0 if v == 60 else (45.0 if (v, loc) == (20, 0.5) else None), skip={(10, 0.9)})
    a = assess_2026(rows)
    v = monte_carlo(a, nominal(a, flip={"CPNA/30/0.5"}), n_draws=50, n_perturbations=4)
    tds = grids_of(render(ncap_2026_report(rows, a, v)))["grid-2026-CPNA-day"]
    tested = [td for td in tds if "data-test" in td]
    assert len(tested) == len(rows) == len(a.cells) and len(tds) == 30  # 6 × 5 grid, one untested
    assert sorted(td["data-test"] for td in tested) == sorted(c.test_id for c in a.cells)
    assert next(td for td in tds if "data-test" not in td)["style"] == f"background:{COLOUR_HEX['untested']}"
    cells = {c.test_id: c for c in a.cells}
    for td in tested:
        c = cells[td["data-test"]]
        assert td["data-colour"] == c.colour and f"background-color:{COLOUR_HEX[c.colour]}" in td["style"]
        assert ("outline" in td["style"]) == (c.range == "extended") == ("extended" in td["class"])
        assert c.test_id in td["title"] and c.criterion in td["title"]
        p = v.pass_probability.get(c.test_id)
        assert json.loads(td["data-pass-probability"]) == p
        assert td["text"] == ("—" if p is None else f"{p:.0%}")
    assert cells["CPNA/20/0.5"].colour == "red" and "CPNA/20/0.5" not in v.pass_probability  # red: never verified
    assert v.pass_probability["CPNA/30/0.5"] == 0.0 and v.pass_probability["CPNA/40/0.5"] == 1.0


def test_html_grid_without_verification_shows_the_kpi():
    rows = cpna(lambda v, loc: 15.0 if v == 60 else None)
    a = assess_2026(rows)
    tds = grids_of(render(ncap_2026_report(rows, a)))["grid-2026-CPNA-day"]
    shown = {td["data-test"]: td["text"] for td in tds}
    assert shown["CPNA/60/0.5"] == "15" and shown["CPNA/10/0.5"] == "✓"
    assert all(td["data-pass-probability"] == "null" for td in tds)


def test_report_totals_equal_the_assessment():
    rows = cpna(lambda v, loc: 25.0 if v >= 50 else None) + cmftap({(10, 30), (25, 80)})
    a = assess_2026(rows)
    v = monte_carlo(a, nominal(a), n_draws=50, n_perturbations=2)
    doc = read_report(render(ncap_2026_report(rows, a, v)))
    for name, points in a.sub_elements.items():
        assert doc.tables["points-2026"][name]["points"] == pytest.approx(points)
    assert doc.tables["points-2026"]["FC Pedestrian & Cyclist"]["max_points"] == 20  # FC26 §3
    for name, p in a.scenarios.items():
        row = doc.tables["scenario-points-2026"][name]
        assert (row["standard"], row["extended"], row["total"]) == pytest.approx((p.standard, p.extended, p.total))
    for name, s in v.scenarios.items():
        row = doc.tables["verification-scenarios"][name]
        assert (row["mean"], row["std"], row["p5"], row["p95"]) == pytest.approx((s.mean, s.std, s.p5, s.p95))
        assert row["predicted"] == pytest.approx(a.scenarios[name].total)
    for name, s in v.sub_elements.items():
        assert doc.tables["verification-sub-elements"][name]["mean"] == pytest.approx(s.mean)
    tests = doc.tables["tests-2026"]
    assert len(tests) == len(rows) and tests["CMFtap/10/30"]["colour"] == "red"


# ----------------------------------------------------------------------------------------------- results folder


def write_folder(folder, rows, a, v=None):
    folder.mkdir()
    pq.write_table(pa.Table.from_pylist(result_rows_2026(rows, a, v)), folder / "results.parquet")
    if v is not None:
        write_verification(v, folder)


def comparable(report) -> dict:
    html = render(report)
    doc = read_report(html)
    results = json.loads(doc.results_text)
    for key in ("code", "source"):
        results.pop(key)
    return {"results": results, "tables": doc.tables, "grids": grids_of(html)}


@pytest.mark.parametrize("verified", [True, False])
def test_report_from_a_results_folder_equals_the_report_from_rows(tmp_path, verified):
    rows = cpna(lambda v, loc: 15.0 if v == 60 else None) + cmftap({(25, 80)})
    a = assess_2026(rows)
    v = monte_carlo(a, nominal(a, flip={"CPNA/30/0.5"}), n_draws=50, n_perturbations=2) if verified else None
    write_folder(tmp_path / "out", rows, a, v)
    from_folder = build_report(str(tmp_path / "out"))
    assert comparable(from_folder) == comparable(ncap_2026_report(rows, a, v))
    sections = [s.anchor for s in from_folder.sections]
    assert ("verification-section" in sections) == verified
    parquet = pq.read_table(tmp_path / "out" / "results.parquet").to_pylist()
    expected = [v.pass_probability.get(r["test_id"]) if v else None for r in rows]
    assert [r["verification_pass_probability"] for r in parquet] == expected


def test_results_rows_carry_the_cells_and_bad_input_is_named(tmp_path):
    rows = cmftap({(15, 45)})
    a = assess_2026(rows)
    out = {r["test_id"]: r for r in result_rows_2026(rows, a)}
    assert out["CMFtap/15/45"]["colour"] == "red" and out["CMFtap/15/45"]["kpi"] == pytest.approx(5.0 / KPH)
    assert out["CMFtap/15/45"]["grid_row_label"] == "15 km/h" and out["CMFtap/15/45"]["grid_column_label"] == "45 km/h"
    assert out["CMFtap/10/30"]["criterion"] == "avoidance (any impact red)"
    with pytest.raises(UserInputError, match="run_rows"):
        result_rows_2026([{**rows[0], "test_id": "nope"}], a)
    (tmp_path / VERIFICATION_FILE).write_text('{"n_draws": 3}')
    with pytest.raises(UserInputError, match=VERIFICATION_FILE):
        read_verification(tmp_path)
    assert read_verification(tmp_path / "missing") is None
    v = monte_carlo(a, nominal(a), n_draws=20, n_perturbations=2)
    assert verification_from_dict(json.loads(json.dumps(v.to_dict()))) == v


# ----------------------------------------------------------------------------------------------- real runs


@pytest.fixture(scope="module")
def real_run():
    from vrusim.ncap.grid import run_tests, select

    tests = [t for t in select(["CPNA", "CMFtap"], protocol="2026") if t.cell.vut_speed_kph > 0]
    rows = run_tests(tests, planner="aeb").rows
    return rows, assess_2026(rows)


def test_real_run_report_and_scorecard_agree(real_run, tmp_path):
    rows, a = real_run
    assert {"CPNA day", "CMFtap"} <= set(a.scenarios)
    write_folder(tmp_path / "out", rows, a)
    report = build_report(str(tmp_path / "out"))
    html = render(report)
    grids = grids_of(html)
    for name in a.scenarios:
        tds = [td for td in grids[f"grid-2026-{name.replace('&', ' ').replace(' ', '-')}"] if "data-test" in td]
        assert {td["data-test"]: td["data-colour"] for td in tds} == {c.test_id: c.colour for c in a.cells_of(name)}
    patches = patches_by_gid(scorecard_2026_figure(a, dpi=40))
    for c in a.cells:
        assert patches[c.test_id].get_facecolor() == pytest.approx(to_rgba(COLOUR_HEX[c.colour]))
    assert f'id="{RESULTS_ID}"' in html
