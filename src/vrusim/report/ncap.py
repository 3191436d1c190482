"""Report of a Euro NCAP assessment: points per group, scores per scenario, the colour grid (HTML and PNG),
and every test (numbers = the `vrusim ncap --out` folder's results.parquet)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from vrusim.errors import UserInputError
from vrusim.ncap.assess import Assessment, assess
from vrusim.report import figures
from vrusim.report.html import Column, Html, cell, facts, filter_box, join, table, tag
from vrusim.report.page import Report, Section
from vrusim.report.parts import metric_column
from vrusim.viz.ncap_colours import COLOUR_HEX
from vrusim.viz.scorecard import scorecard_figure
from vrusim.viz.scorecard_cells import CAPTION, GROUP_TITLES, cell_text, group_grid, panel_title, row_label

TEST_COLUMNS = (
    Column("scenario", "Scenario"),
    Column("lighting", "Light"),
    Column("vut_speed_kph", "VUT (km/h)", 1),
    Column("variant", "Variant"),
    Column("target", "Target"),
    Column("collided", "Collided"),
    Column("impact_speed_kph", "Impact (km/h)", 2),
    Column("relative_impact_speed_kph", "Relative impact (km/h)", 2),
    Column("speed_reduction_kph", "Reduction (km/h)", 2),
    metric_column("warning_ttc_s", 2),
    metric_column("min_ttc_s", 2),
    Column("criterion", "Criterion"),
    Column("colour", "Colour"),
    Column("sub_score", "Sub-score", 3),
)
"""Columns of the per-test table (keys of the results.parquet rows)."""


def read_rows(folder: Path) -> list[dict[str, Any]]:
    """The rows of FOLDER/results.parquet as written; an unreadable file is a user error naming it."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    path = folder / "results.parquet"
    try:
        return pq.read_table(path).to_pylist()
    except (OSError, pa.ArrowException) as error:
        raise UserInputError(f"SOURCE: cannot read {path} ({error})") from None


def read_results(folder: Path) -> list[dict[str, Any]]:
    """The rows of FOLDER/results.parquet of a 2023-protocol run; an unreadable file is a user error naming it."""
    path = folder / "results.parquet"
    rows = read_rows(folder)
    missing = {"test_id", "scenario", "colour", "sub_score"} - set(rows[0] if rows else {})
    if not rows or missing:
        raise UserInputError(f"SOURCE: {path} is not a `vrusim ncap` results file (no tests or missing columns)")
    return rows


def points_table(assessment: Assessment) -> Html:
    """Points per group and the Euro NCAP total (extension groups listed, not added)."""
    rows = [
        (
            g.group,
            {
                "group": GROUP_TITLES.get(g.group, g.group),
                "points": g.score,
                "max_points": g.max_points,
                "in_total": g.in_euro_ncap_total,
                "not_assessed": ", ".join(g.not_assessed) or "—",
            },
        )
        for g in assessment.groups
    ]
    total = [("total", {"group": "Total", "points": assessment.total, "max_points": assessment.total_max})]
    columns = [
        Column("points", "Points", 2),
        Column("max_points", "Max", 2),
        Column("in_total", "In Euro NCAP total"),
        Column("not_assessed", "Not assessed"),
    ]
    return table(
        "points",
        columns,
        rows,
        "Euro NCAP VRU AEB points per group.",
        row_header=Column("group", "Group"),
        totals=total,
    )


def scenario_table(assessment: Assessment) -> Html:
    """Score of each (scenario, lighting): sub-scores × points / cells."""
    rows = [
        (
            f"{s.scenario}/{s.lighting}",
            {
                "scenario": s.scenario,
                "lighting": s.lighting,
                "group": s.group,
                "cells": s.cells,
                "sub_score_sum": s.sub_score_sum,
                "points": s.points,
                "score": s.score,
            },
        )
        for g in assessment.groups
        for s in g.scenarios
    ]
    columns = [
        Column("lighting", "Light"),
        Column("group", "Group"),
        Column("cells", "Cells"),
        Column("sub_score_sum", "Σ sub-scores", 3),
        Column("points", "Points available", 3),
        Column("score", "Score", 3),
    ]
    return table("scenario-scores", columns, rows, row_header=Column("scenario", "Scenario"))


def colour_grids(assessment: Assessment) -> Html:
    """Per group an HTML grid: rows scenario / lighting, columns VUT speed, cells in their Euro NCAP colour."""
    parts = []
    for group in assessment.groups:
        tests = [test for test in assessment.tests if test.group == group.group]
        if not tests:
            continue
        rows, speeds, cells = group_grid(tests)
        head = tag("thead", tag("tr", tag("th", "Scenario"), *(tag("th", f"{s:g}") for s in speeds)))
        body = []
        for row in rows:
            tds = []
            for speed in speeds:
                test = cells.get((row, speed))
                if test is None:
                    tds.append(tag("td", "", class_="swatch", style=f"background:{COLOUR_HEX['untested']}"))
                    continue
                ink = "#fff" if test.colour in ("brown", "red") else "#000"
                tip = f"{test.test_id}: {test.outcome}, {test.colour}, sub-score {test.sub_score:.3f}"
                tds.append(
                    cell(
                        "colour",
                        test.colour,
                        shown=cell_text(test),
                        class_="swatch",
                        title=tip,
                        data_test=test.test_id,
                        style=f"background:{COLOUR_HEX[test.colour]};color:{ink}",
                    )
                )
            body.append(tag("tr", tag("th", row_label(row), scope="row"), *tds))
        grid = tag("table", head, tag("tbody", *body), id=f"grid-{group.group}", class_="grid")
        parts.append(tag("h3", panel_title(group)) + tag("div", grid, class_="table-wrap"))
    return join(
        [*parts, tag("p", CAPTION + " Columns: VUT test speed (km/h). Hover a cell for its test.", class_="note")]
    )


def tests_table(rows: list[dict[str, Any]]) -> Html:
    """Every test, filterable and sortable."""
    keyed = [(row["test_id"], row) for row in rows]
    return join(
        [
            filter_box("tests", "Filter tests (e.g. CPNA night red)…"),
            table("tests", TEST_COLUMNS, keyed, row_header=Column("test_id", "Test")),
        ]
    )


def ncap_report(rows: list[dict[str, Any]], assessment: Assessment, source: str | None = None) -> Report:
    """The report of assessed catalogue tests (`rows` as in results.parquet)."""
    planners = sorted({str(row.get("planner")) for row in rows})
    v2x = sorted({"on" if row.get("v2x") else "off" for row in rows})
    what = [
        ("tests", str(len(rows))),
        ("scenarios", ", ".join(dict.fromkeys(row["scenario"] for row in rows))),
        ("lighting", ", ".join(sorted({row["lighting"] for row in rows}))),
        ("planner", ", ".join(planners)),
        ("V2X", ", ".join(v2x)),
        (
            "total",
            tag(
                "span",
                f"{assessment.total:.2f} / {assessment.total_max:g} points",
                id="total-points",
                data_value=repr(assessment.total),
            ),
        ),
    ]
    if source:
        what.insert(0, ("results", source))
    png = figures.figure(
        scorecard_figure(assessment),
        "Euro NCAP scorecard",
        "The scorecard as `vrusim ncap --out` draws it (scorecard.png).",
        "scorecard",
    )
    notes = join(tag("li", note) for note in assessment.notes)
    sections = [
        Section("what-was-run", "What was assessed", facts(what, "ncap-facts")),
        Section("points-section", "Points", join([points_table(assessment), scenario_table(assessment)])),
        Section("scorecard-section", "Scorecard", join([colour_grids(assessment), png])),
        Section("tests-section", "Tests", tests_table(rows)),
        Section("notes", "Caveats", tag("ul", notes)),
    ]
    return Report(
        kind="ncap",
        title="vrusim Euro NCAP AEB VRU assessment",
        lead=f"{len(rows)} tests, planner {', '.join(planners)}, V2X {', '.join(v2x)}: "
        f"{assessment.total:.2f} / {assessment.total_max:g} Euro NCAP points.",
        sections=sections,
        results={"source": source, "rows": rows, "assessment": assessment.to_dict()},
    )


def ncap_report_from_folder(folder: Path) -> Report:
    """The report of a `vrusim ncap --out` folder: its results.parquet, assessed again for group points; rows of
    protocol "2026" make the 2026 report (`report.ncap2026`)."""
    rows = read_rows(folder)
    if rows and rows[0].get("protocol") == "2026":
        from vrusim.report.ncap2026 import ncap_2026_report_from_rows

        return ncap_2026_report_from_rows(rows, folder)
    rows = read_results(folder)
    try:
        assessment = assess(rows)
    except (KeyError, ValueError, TypeError) as error:
        raise UserInputError(f"SOURCE: {folder / 'results.parquet'} cannot be assessed ({error})") from None
    return ncap_report(rows, assessment, str(folder))
