"""Report of a Euro NCAP 2026 assessment: sub-element totals, points per scenario, the grids as FC26 / LSC26 lay
them out (HTML and PNG), the simulated lab verification when it was run, and every test.

Rows are `ncap.grid.run_tests` rows (protocol "2026") or the results.parquet rows of a `vrusim ncap --protocol
2026 --out` folder; both are joined with their cells (`result_rows_2026`), so a folder gives the same report.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from vrusim.errors import UserInputError
from vrusim.ncap.rating2026 import Assessment2026, CellResult2026, assess_2026
from vrusim.ncap.rating2026 import tables as t
from vrusim.ncap.results2026 import kpi_unit, read_verification, result_rows_2026
from vrusim.ncap.verification import VerificationReport
from vrusim.report import figures
from vrusim.report.html import Column, Html, cell, facts, filter_box, join, table, tag
from vrusim.report.page import Report, Section
from vrusim.report.parts import metric_column
from vrusim.viz.ncap_colours import COLOUR_HEX
from vrusim.viz.scorecard2026 import scorecard_2026_figure
from vrusim.viz.scorecard2026_cells import (
    AXIS_TITLES,
    grid_cells,
    kpi_text,
    panels,
    scenario_max_points,
    sub_element_max_points,
)

TEST_COLUMNS_2026 = (
    Column("official_scenario", "Scenario"),
    Column("scenario", "Code"),
    Column("lighting", "Light"),
    Column("range", "Range"),
    Column("function", "Function"),
    Column("grid_row_label", "Grid row"),
    Column("grid_column_label", "Grid column"),
    Column("target_speed_kph", "Target (km/h)", 1),
    Column("collided", "Collided"),
    Column("impact_speed_mps", "Impact (m/s)", 2),
    metric_column("warning_ttc_s", 2),
    Column("criterion", "Criterion"),
    Column("kpi", "KPI (km/h or s)", 2),
    Column("colour", "Colour"),
    Column("verification_pass_probability", "Pass probability", 2),
)
"""Columns of the per-test table (keys of the 2026 results rows)."""
EXTENDED_STYLE = (
    "outline:2px dashed #222;outline-offset:-4px;"
    "background-image:repeating-linear-gradient(45deg,transparent 0 5px,rgba(255,255,255,.35) 5px 7px)"
)
"""Extended-range cells: a dashed frame and light stripes over the colour (inline: the page allows no CDN)."""
NOTE = (
    "Rows: VUT speed (FCW rows last; LSC: distance / gap), columns: impact location (100 % first) or target speed, "
    "as FC26 §3 / LSC26 §3 print the grids. Dashed, striped cells: extended range; grey: no test. Hover a cell for "
    "its test, KPI and criterion."
)


def slug(name: str) -> str:
    """An id fragment of a scenario name: "CPTAfs & CPTAns" -> "CPTAfs-CPTAns"."""
    return "-".join(name.replace("&", " ").split())


def points_table(assessment: Assessment2026) -> Html:
    """Points per sub-element (assessed scenarios) with the maximum of all its VRU scenarios."""
    rows = [
        (
            name,
            {
                "sub_element": name,
                "points": assessment.sub_elements[name],
                "max_points": sub_element_max_points(name),
                "scenarios": len(names),
            },
        )
        for name, names in panels(assessment)
    ]
    columns = [Column("points", "Points", 2), Column("max_points", "Max", 3), Column("scenarios", "Scenarios assessed")]
    caption = "Points per sub-element before verification (FC26 §5.3, LSC26)."
    return table("points-2026", columns, rows, caption, row_header=Column("sub_element", "Sub-element"))


def scenario_table(assessment: Assessment2026) -> Html:
    """Points of each scenario by range (FC26 §5.3: standard, extended, robustness) and its maximum."""
    rows = []
    for name, names in panels(assessment):
        for scenario in names:
            p = assessment.scenarios[scenario]
            rows.append(
                (
                    scenario,
                    {
                        "scenario": scenario,
                        "sub_element": name,
                        "standard": p.standard,
                        "extended": p.extended,
                        "robustness": p.robustness,
                        "total": p.total,
                        "max_points": scenario_max_points(scenario),
                        "n_standard": p.n_standard,
                        "n_extended": p.n_extended,
                    },
                )
            )
    columns = [
        Column("sub_element", "Sub-element"),
        Column("standard", "Standard", 3),
        Column("extended", "Extended", 3),
        Column("robustness", "Robustness", 3),
        Column("total", "Total", 3),
        Column("max_points", "Max", 4),
        Column("n_standard", "Standard cells"),
        Column("n_extended", "Extended cells"),
    ]
    return table("scenario-points-2026", columns, rows, row_header=Column("scenario", "Scenario"))


def cell_tip(c: CellResult2026, probability: float | None, verified: bool) -> str:
    """A cell's tooltip: test id, range, criterion, KPI with unit, colour, pass probability."""
    kpi = "—" if c.kpi is None else f"{c.kpi:.2f} {kpi_unit(c.criterion)}"
    tip = f"{c.test_id} · {c.range} · {c.criterion}: KPI {kpi} → {c.colour}"
    if verified:
        tip += " · pass probability " + (
            "— (not a verification candidate)" if probability is None else f"{probability:.0%}"
        )
    return tip


def probability_shown(probability: float | None) -> str:
    """A pass probability as a cell shows it: whole percent, "—" for a cell the lab never picks."""
    return "—" if probability is None else f"{probability:.0%}"


def grid_html(assessment: Assessment2026, scenario: str, verification: VerificationReport | None) -> Html:
    """One scenario's grid as an HTML table: a `<td>` per cell in its colour (data-test, data-colour, data-range,
    data-pass-probability), extended cells framed and striped, grey without a test."""
    grid, cells = grid_cells(assessment, scenario)
    axis = AXIS_TITLES.get(grid.column_axis, grid.column_axis)
    head = tag("thead", tag("tr", tag("th", f"VUT \\ {axis}"), *(tag("th", c, scope="col") for c in grid.columns)))
    body = []
    for row in grid.rows:
        tds = []
        for column in grid.columns:
            c = cells.get((row, column))
            if c is None:
                tds.append(tag("td", "", class_="swatch untested", style=f"background:{COLOUR_HEX['untested']}"))
                continue
            probability = verification.pass_probability.get(c.test_id) if verification is not None else None
            ink = "#fff" if c.colour in ("brown", "red") else "#000"
            style = f"background-color:{COLOUR_HEX[c.colour]};color:{ink}"
            if c.range == "extended":
                style += f";{EXTENDED_STYLE}"
            shown = kpi_text(c) if verification is None else probability_shown(probability)
            tds.append(
                cell(
                    "colour",
                    c.colour,
                    shown=shown,
                    class_=f"swatch {c.range}",
                    title=cell_tip(c, probability, verification is not None),
                    style=style,
                    data_test=c.test_id,
                    data_colour=c.colour,
                    data_range=c.range,
                    data_pass_probability="null" if probability is None else repr(probability),
                )
            )
        body.append(tag("tr", tag("th", row, scope="row"), *tds))
    points = assessment.scenarios[scenario]
    title = tag(
        "h4",
        f"{scenario}: ",
        tag("span", f"{points.total:.2f}", class_="points", data_value=repr(points.total)),
        f" / {scenario_max_points(scenario):g} points",
    )
    grid_table = tag("table", head, tag("tbody", *body), id=f"grid-2026-{slug(scenario)}", class_="grid",
                     data_scenario=scenario)  # fmt: skip
    return title + tag("div", grid_table, class_="table-wrap")


def grids_html(assessment: Assessment2026, verification: VerificationReport | None) -> Html:
    """Every scenario's grid, under a heading per sub-element with its points."""
    parts = []
    for name, names in panels(assessment):
        total = assessment.sub_elements[name]
        parts.append(tag("h3", f"{name}: {total:.2f} / {sub_element_max_points(name):g} points"))
        parts += [grid_html(assessment, scenario, verification) for scenario in names]
    shown = "verification pass probability" if verification is not None else "KPI (km/h; FCW rows: warning TTC, s)"
    parts.append(tag("p", f"{NOTE} Cells show the {shown}.", class_="note"))
    return join(parts)


def verification_section(assessment: Assessment2026, verification: VerificationReport) -> Html:
    """Expected points after the simulated lab verification (mean, std, 5 / 95 %) per sub-element and scenario."""
    about = facts(
        [
            ("lab draws", str(verification.n_draws)),
            ("runs per cell", str(verification.n_perturbations)),
            ("seed", str(verification.seed)),
            ("prediction method", verification.method),
            ("cells verified", str(len(verification.pass_probability))),
        ],
        "verification-facts",
    )
    columns = [
        Column("predicted", "Predicted", 3),
        Column("mean", "Expected (mean)", 3),
        Column("std", "Std", 3),
        Column("p5", "5 %", 3),
        Column("p95", "95 %", 3),
    ]

    def rows(spreads: Mapping[str, Any], predicted: Mapping[str, float], names: list[str], key: str) -> list:
        return [
            (name, {key: name, "predicted": predicted[name], **spreads[name].__dict__})
            for name in names
            if name in spreads
        ]

    sub_names = [name for name, _ in panels(assessment)]
    scenario_names = [s for _, names in panels(assessment) for s in names]
    predicted = {name: p.total for name, p in assessment.scenarios.items()}
    return join(
        [
            about,
            table(
                "verification-sub-elements",
                columns,
                rows(verification.sub_elements, assessment.sub_elements, sub_names, "sub_element"),
                "Points after verification, per sub-element (FC26 §4.2, §5.3.4; Monte Carlo over lab draws).",
                row_header=Column("sub_element", "Sub-element"),
            ),
            table(
                "verification-scenarios",
                columns,
                rows(verification.scenarios, predicted, scenario_names, "scenario"),
                "Points after verification, per scenario.",
                row_header=Column("scenario", "Scenario"),
            ),
            tag(
                "p",
                "Each draw is one lab visit: 3–5 standard and 2 extended cells per FC scenario drawn among the "
                "non-red, non-corner-case predictions, each run once within FC26 §4.3.2's tolerances; a cell's pass "
                "probability (in the grids) is the share of its perturbed runs that confirm its colour within "
                "±2 km/h (§4.2.4).",
                class_="note",
            ),
        ]
    )


def tests_table(rows: list[dict[str, Any]]) -> Html:
    """Every test, filterable and sortable."""
    keyed = [(str(row["test_id"]), row) for row in rows]
    return join(
        [
            filter_box("tests-2026", "Filter tests (e.g. CPNA night red)…"),
            table("tests-2026", TEST_COLUMNS_2026, keyed, row_header=Column("test_id", "Test")),
        ]
    )


def ncap_2026_report(
    rows: list[dict[str, Any]],
    assessment: Assessment2026,
    verification: VerificationReport | None = None,
    source: str | None = None,
) -> Report:
    """The report of a 2026 assessment (`rows`: run rows or results rows; `verification`: the lab Monte Carlo)."""
    rows = result_rows_2026(rows, assessment, verification)
    planners = sorted({str(row.get("planner")) for row in rows})
    v2x = sorted({"on" if row.get("v2x") else "off" for row in rows})
    totals = [
        (name, tag("span", f"{assessment.sub_elements[name]:.2f} / {sub_element_max_points(name):g} points",
                   class_="sub-element-points", data_sub_element=name, data_value=repr(assessment.sub_elements[name])))
        for name, _ in panels(assessment)
    ]  # fmt: skip
    what = [
        ("protocol", "Euro NCAP 2026 (FC26 v1.1, LSC26 v1.1)"),
        ("tests", str(len(rows))),
        ("scenarios", ", ".join(s for _, names in panels(assessment) for s in names)),
        ("planner", ", ".join(planners)),
        ("V2X", ", ".join(v2x)),
        *totals,
    ]
    if source:
        what.insert(0, ("results", source))
    png = figures.figure(
        scorecard_2026_figure(assessment, verification=verification),
        "Euro NCAP 2026 scorecard",
        "The 2026 scorecard as `vrusim ncap --protocol 2026 --out` draws it (scorecard.png).",
        "scorecard-2026",
    )
    sections = [
        Section("what-was-run", "What was assessed", facts(what, "ncap-facts")),
        Section("points-section", "Points", join([points_table(assessment), scenario_table(assessment)])),
        Section("scorecard-section", "Scorecard", join([grids_html(assessment, verification), png])),
    ]
    if verification is not None:
        sections.append(Section("verification-section", "Verification", verification_section(assessment, verification)))
    sections += [
        Section("tests-section", "Tests", tests_table(rows)),
        Section("notes", "Caveats (UNVERIFIED)", tag("ul", *(tag("li", note) for note in t.UNVERIFIED))),
    ]
    lead = "; ".join(f"{name} {value:.2f}" for name, value in assessment.sub_elements.items())
    return Report(
        kind="ncap",
        title="vrusim Euro NCAP 2026 VRU crash-avoidance assessment",
        lead=f"{len(rows)} tests, planner {', '.join(planners)}, V2X {', '.join(v2x)}: {lead} points "
        "(before verification).",
        sections=sections,
        results={
            "source": source,
            "protocol": "2026",
            "rows": rows,
            "assessment": assessment.to_dict(),
            "verification": verification.to_dict() if verification is not None else None,
        },
    )


def ncap_2026_report_from_rows(rows: list[dict[str, Any]], folder: Path) -> Report:
    """The report of a 2026 results folder: its rows assessed again, verification.json when there is one."""
    try:
        assessment = assess_2026(rows)
    except (KeyError, ValueError, TypeError) as error:
        raise UserInputError(f"SOURCE: {folder / 'results.parquet'} cannot be assessed ({error})") from None
    return ncap_2026_report(rows, assessment, read_verification(folder), str(folder))
