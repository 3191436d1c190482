"""Every report kind opened in headless Chromium (Debian's /usr/bin/chromium, driven by Playwright; no browser
download): no console or page errors, every image and plot drawn with a size, the charts answer the pointer,
and the numbers in the tables equal the results files (run --json, paper --json, results.parquet, the sweep's
Parquet chunks), each parsed here on its own.

Chromium missing is a failure naming the fix (`scripts/install-test-deps.sh`), not a skip, unless
VRUSIM_SKIP_BROWSER_TESTS=1 opts out.
"""

from __future__ import annotations

import json
import math
import os
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow.parquet as pq
import pytest
import yaml

from cli_helpers import invoke
from conftest import PAPER_DIR, REPO_ROOT
from report_helpers import same, wilson

CHROMIUM = Path(os.environ.get("VRUSIM_CHROMIUM", "/usr/bin/chromium"))
OPT_OUT = "VRUSIM_SKIP_BROWSER_TESTS"
EXAMPLE = REPO_ROOT / "scenarios" / "examples" / "right_turn_cyclist.yaml"
NCAP_SCENARIOS = ("CPNA-25", "CBLA-50")

TABLES_JS = """() => {
  const out = {};
  for (const table of document.querySelectorAll('table.data')) {
    const rows = {};
    for (const tr of table.tBodies[0].rows) {
      const cells = {};
      for (const td of tr.querySelectorAll('td[data-col]')) {
        cells[td.dataset.col] = {value: JSON.parse(td.dataset.value), text: td.innerText.trim(),
                                 digits: td.dataset.digits === undefined ? null : Number(td.dataset.digits)};
      }
      rows[tr.dataset.row] = cells;
    }
    out[table.id] = rows;
  }
  return out;
}"""

RENDERED_JS = """() => ({
  images: [...document.images].map(i => ({id: i.closest('figure')?.id, complete: i.complete,
                                          natural: i.naturalWidth * i.naturalHeight,
                                          box: i.getBoundingClientRect().width * i.getBoundingClientRect().height})),
  charts: [...document.querySelectorAll('div.chart')].map(c => {
    const svg = c.querySelector('svg'), box = svg.getBoundingClientRect();
    const drawn = [...svg.querySelectorAll('g.series path')].filter(p => p.getTotalLength() > 0).length;
    return {id: c.id, ready: c.dataset.ready === 'true', area: box.width * box.height, drawn};
  }),
  svgs: [...document.querySelectorAll('svg')].map(s => {
    const box = s.getBoundingClientRect();
    return box.width * box.height;
  }),
  ready: document.body.dataset.ready === 'true',
})"""


# ----------------------------------------------------------------------------------------------- browser


@pytest.fixture(scope="module")
def browser():
    """Headless Chromium from the system package; a clear failure when it is missing."""
    if os.environ.get(OPT_OUT) == "1":
        pytest.skip(f"browser tests switched off by {OPT_OUT}=1")
    if not CHROMIUM.is_file():
        pytest.fail(
            f"Chromium not found at {CHROMIUM}: install it with `bash scripts/install-test-deps.sh` "
            f"(Debian's chromium package), or set {OPT_OUT}=1 to skip the browser tests",
            pytrace=False,
        )
    from playwright.sync_api import sync_playwright

    with sync_playwright() as playwright:
        chromium = playwright.chromium.launch(executable_path=str(CHROMIUM), args=["--no-sandbox"])
        yield chromium
        chromium.close()


def open_report(browser, path: Path) -> tuple[Any, list[str]]:
    """A page showing the report, and the list that collects its console errors, warnings and page errors."""
    page = browser.new_page(viewport={"width": 1280, "height": 900})
    problems: list[str] = []
    page.on("console", lambda m: problems.append(f"{m.type}: {m.text}") if m.type in ("error", "warning") else None)
    page.on("pageerror", lambda error: problems.append(f"page error: {error}"))
    page.on("requestfailed", lambda request: problems.append(f"request failed: {request.url}"))
    page.goto(path.resolve().as_uri(), wait_until="load")
    page.wait_for_selector("body[data-ready='true']", timeout=10_000)
    return page, problems


def check_rendered(page, problems: list[str], charts_expected: int) -> dict[str, dict]:
    """No errors; every image decoded and laid out; every chart scripted and drawn; hovering answers. Tables."""
    rendered = page.evaluate(RENDERED_JS)
    assert rendered["ready"]
    assert rendered["images"], "no images"
    for image in rendered["images"]:
        assert image["complete"] and image["natural"] > 0 and image["box"] > 0, image
    assert len(rendered["charts"]) >= charts_expected
    for chart in rendered["charts"]:
        assert chart["ready"] and chart["area"] > 0 and chart["drawn"] >= 1, chart
    assert all(area > 0 for area in rendered["svgs"])
    if rendered["charts"]:
        chart = page.locator("div.chart").first
        chart.scroll_into_view_if_needed()
        box = chart.locator("svg").bounding_box()
        page.mouse.move(box["x"] + box["width"] * 0.5, box["y"] + box["height"] * 0.5)
        assert " = " in chart.locator(".readout").inner_text()
        assert chart.locator(".crosshair").get_attribute("visibility") == "visible"
        chart.locator(".legend button").first.click()
        assert chart.locator(".legend button").first.get_attribute("aria-pressed") == "false"
    assert problems == []
    return page.evaluate(TABLES_JS)


def assert_cell(cell: dict, expected: Any, tolerance: float = 1e-9) -> None:
    """The cell's exact value equals `expected`, and its text shows it rounded to the cell's digits."""
    assert same(cell["value"], expected, tolerance), (cell, expected)
    if cell["digits"] is not None and expected is not None and not isinstance(expected, bool):
        shown = float(cell["text"].split()[0].replace("−", "-"))
        assert math.isclose(shown, expected, abs_tol=0.5 * 10 ** -cell["digits"] + 1e-12), (cell, expected)


def write(tmp: Path, name: str, *args) -> Path:
    result = invoke(*args)
    assert result.exit_code == 0, result.output
    return tmp / name


# ----------------------------------------------------------------------------------------------- the four kinds


def test_run_report_in_browser(browser, tmp_path):
    out = write(tmp_path, "run.html", "report", EXAMPLE, "--out", tmp_path / "run.html")
    row = json.loads(invoke("run", EXAMPLE, "--json").stdout)
    page, problems = open_report(browser, out)
    tables = check_rendered(page, problems, charts_expected=3)
    for key, value in row.items():
        if not isinstance(value, dict | list):
            assert_cell(tables["summary"][key]["value"], value)
    for index, transition in enumerate(row["transitions"]):
        assert_cell(tables["transitions"][str(index)]["t_s"], transition["t_s"])


def test_paper_report_in_browser(browser, tmp_path):
    result = invoke("paper", "--json", "--report", tmp_path / "paper.html")
    assert result.exit_code == 0, result.output
    document = json.loads(result.stdout)
    page, problems = open_report(browser, tmp_path / "paper.html")
    tables = check_rendered(page, problems, charts_expected=18)
    table_ii = tables["table-ii"]
    assert len(table_ii) == len(document["cases"]) == 6
    for case in document["cases"]:
        row = table_ii[f"{case['case']}/{'on' if case['v2x'] else 'off'}"]
        for name in ("safety", "efficiency", "comfort"):
            assert_cell(row[f"{name}_paper"], case["paper"][name])
            assert_cell(row[f"{name}_ours"], case["ours"][name])
            assert_cell(row[f"{name}_diff"], case["ours"][name] - case["paper"][name])
        assert row["outcome_ours"]["value"] == ("collision" if case["ours"]["collided"] else "avoided")
    for index, event in enumerate(document["events"]):
        assert_cell(tables["events"][str(index)]["paper_s"], event["paper_s"])
        assert_cell(tables["events"][str(index)]["ours_s"], event["ours_s"])
    assert page.locator("figure img").count() == 6  # snapshots and time series of each case


def test_ncap_report_in_browser(browser, tmp_path):
    folder = tmp_path / "ncap"
    selection = [arg for code in NCAP_SCENARIOS for arg in ("--scenario", code)]
    result = invoke(
        "ncap", "--protocol", "2023", *selection, "--out", folder, "--report", tmp_path / "direct.html", "--json"
    )
    assert result.exit_code == 0, result.output
    assessment = json.loads(result.stdout)["assessment"]
    write(tmp_path, "ncap.html", "report", folder, "--out", tmp_path / "ncap.html")
    rows = pq.read_table(folder / "results.parquet").to_pylist()
    for name in ("ncap.html", "direct.html"):
        page, problems = open_report(browser, tmp_path / name)
        tables = check_rendered(page, problems, charts_expected=0)
        assert set(tables["tests"]) == {row["test_id"] for row in rows}
        for row in rows:
            cells = tables["tests"][row["test_id"]]
            for key in ("vut_speed_kph", "collided", "impact_speed_kph", "relative_impact_speed_kph", "colour",
                        "sub_score", "warning_ttc_s", "min_ttc_s"):  # fmt: skip
                assert_cell(cells[key], row[key])
        for group in assessment["groups"]:
            assert_cell(tables["points"][group["group"]]["points"], group["score"])
            assert_cell(tables["points"][group["group"]]["max_points"], group["max_points"])
        assert_cell(tables["points"]["total"]["points"], assessment["total"])
        grid_cells = page.locator("table.grid td[data-test]")
        assert grid_cells.count() == len(rows)
        page.fill("input.filter", "CBLA")
        visible = page.locator("#tests tbody tr:visible").count()
        assert visible == sum(row["scenario"].startswith("CBLA") for row in rows)


SWEEP_SPEC = {
    "name": "browser <sweep> & test",
    "base": str(PAPER_DIR / "pedestrian_crossing.yaml"),
    "parameters": {"ego.cruise_speed_mps": {"uniform": [8.0, 18.0]}, "v2x.enabled": [False, True]},
    "samples": 10,
    "seed": 3,
    "batch_size": 10,
}


def test_sweep_report_in_browser(browser, tmp_path):
    spec = tmp_path / "sweep.yaml"
    spec.write_text(yaml.safe_dump(SWEEP_SPEC))
    folder = tmp_path / "results"
    result = invoke("sweep", spec, "--out", folder, "--workers", "1", "--quiet")
    assert result.exit_code == 0, result.output
    out = write(tmp_path, "sweep.html", "report", folder, "--out", tmp_path / "sweep.html", "--bins", "5")
    table = pq.ParquetDataset(sorted((folder / "chunks").glob("chunk-*.parquet"))).read()
    collided = np.array(table.column("collided").to_pylist())
    speed = np.array(table.column("ego.cruise_speed_mps").to_pylist())
    v2x = np.array(table.column("v2x.enabled").to_pylist())
    assert len(collided) == 20 and 0 < collided.sum() < 20
    page, problems = open_report(browser, out)
    tables = check_rendered(page, problems, charts_expected=1)
    overall = tables["overall"]["all"]
    assert_cell(overall["runs"], 20)
    assert_cell(overall["collisions"], int(collided.sum()))
    low, high = wilson(int(collided.sum()), 20)
    assert_cell(overall["p_low"], low, 1e-6)
    assert_cell(overall["p_high"], high, 1e-6)
    bins = tables["by-0"]
    assert sum(row["runs"]["value"] for row in bins.values()) == 20
    assert math.isclose(min(row["bin_low"]["value"] for row in bins.values()), speed.min())
    assert math.isclose(max(row["bin_high"]["value"] for row in bins.values()), speed.max())
    for row in bins.values():
        lo, hi = row["bin_low"]["value"], row["bin_high"]["value"]
        inside = (speed >= lo) & ((speed < hi) | (hi == speed.max()))
        assert_cell(row["runs"], int(inside.sum()))
        assert_cell(row["collisions"], int(collided[inside].sum()))
        assert_cell(row["p"], collided[inside].mean())
    for row in tables["by-1"].values():
        chosen = v2x == row["value"]["value"]
        assert_cell(row["collisions"], int(collided[chosen].sum()))
        low, high = wilson(int(collided[chosen].sum()), int(chosen.sum()))
        assert_cell(row["p_low"], low, 1e-6)
        assert_cell(row["p_high"], high, 1e-6)
    assert page.title() == "vrusim sweep: browser <sweep> & test"
