"""Euro NCAP 2026 scorecard for the terminal (Rich): each sub-element's grids, the colour key, the points and,
after a simulated verification, the expected points."""

from __future__ import annotations

from rich import box
from rich.console import Group, RenderableType
from rich.table import Table
from rich.text import Text

from vrusim.ncap.rating2026 import Assessment2026
from vrusim.ncap.rating2026 import tables as t
from vrusim.ncap.verification import VerificationReport
from vrusim.viz.ncap_colours import COLOUR_HEX, ink
from vrusim.viz.scorecard2026_cells import (
    compact_column,
    compact_row,
    grid_cells,
    panels,
    scenario_max_points,
    sub_element_max_points,
    sub_element_title,
)


def grid_table(assessment: Assessment2026, scenario: str) -> Group:
    """A scenario's title (points / max) and compact grid: one coloured block per cell ("e": extended range,
    "·": no test)."""
    grid, cells = grid_cells(assessment, scenario)
    table = Table(
        box=None,
        padding=(0, 0),
        show_edge=False,
    )
    corner = "IL%" if grid.column_axis == "impact_location" else "tgt"
    table.add_column(corner, no_wrap=True)
    for column in grid.columns:
        table.add_column(compact_column(column).rjust(3), justify="center", no_wrap=True, min_width=4)
    for row in grid.rows:
        blocks = []
        for column in grid.columns:
            cell = cells.get((row, column))
            if cell is None:
                blocks.append(Text(" · ", style="dim"))
            else:
                mark = " e " if cell.range == "extended" else "   "
                blocks.append(Text(mark, style=f"{ink(cell.colour)} on {COLOUR_HEX[cell.colour]}"))
        table.add_row(compact_row(row) + " ", *blocks)
    title = f"{scenario} {assessment.scenarios[scenario].total:.2f}/{scenario_max_points(scenario):g}"
    return Group(Text(title, style="bold", no_wrap=True), table)


def sub_element_grids(assessment: Assessment2026, name: str, scenarios: list[str]) -> Group:
    """A sub-element's title and its scenario grids, two side by side (fits 80 columns)."""
    layout = Table.grid(padding=(0, 3))
    layout.add_column(vertical="top")
    layout.add_column(vertical="top")
    for k in range(0, len(scenarios), 2):
        pair = [grid_table(assessment, s) for s in scenarios[k : k + 2]]
        layout.add_row(*pair, *([""] * (2 - len(pair))))
    return Group(Text(sub_element_title(assessment, name), style="bold underline"), layout)


def legend_text() -> Text:
    """The colour key of the terminal grids."""
    text = Text()
    for colour in t.COLOURS:
        text.append("   ", style=f"on {COLOUR_HEX[colour]}")
        text.append(f" {colour}  ")
    text.append(" e ", style="black on #cfcfcf")
    text.append(" extended  ")
    text.append(" · ", style="dim")
    text.append(" no test")
    return text


def points_table(assessment: Assessment2026) -> Table:
    """Points per scenario by range, and per sub-element (bold), with the maxima."""
    table = Table(title="Euro NCAP 2026 VRU points (before verification)", box=box.SIMPLE_HEAD, title_justify="left")
    table.add_column("Scenario")
    for title in ("Std", "Ext", "Rob", "Total", "Max"):
        table.add_column(title, justify="right")
    for name, scenarios in panels(assessment):
        for scenario in scenarios:
            p = assessment.scenarios[scenario]
            values = (p.standard, p.extended, p.robustness, p.total)
            table.add_row(scenario, *(f"{v:.2f}" for v in values), f"{scenario_max_points(scenario):g}")
        table.add_row(
            Text(name, style="bold"),
            "",
            "",
            "",
            Text(f"{assessment.sub_elements[name]:.2f}", style="bold"),
            f"{sub_element_max_points(name):g}",
            end_section=True,
        )
    return table


def spread_text(mean: float, std: float) -> str:
    return f"{mean:.2f} ± {std:.2f}"


def verification_table(assessment: Assessment2026, verification: VerificationReport) -> Table:
    """Expected points after the simulated lab verification: mean ± std and the 5–95 % range, per scenario and
    sub-element (bold), next to the predicted points."""
    title = (
        f"After verification ({verification.n_draws} lab draws × {verification.n_perturbations} runs per cell, "
        f"{verification.method})"
    )
    table = Table(title=title, box=box.SIMPLE_HEAD, title_justify="left")
    table.add_column("Scenario")
    table.add_column("Predicted", justify="right")
    table.add_column("Mean ± std", justify="right")
    table.add_column("5–95 %", justify="right")
    for name, scenarios in panels(assessment):
        for scenario in scenarios:
            s = verification.scenarios.get(scenario)
            if s is None:
                continue
            predicted = assessment.scenarios[scenario].total
            table.add_row(scenario, f"{predicted:.2f}", spread_text(s.mean, s.std), f"{s.p5:.2f}–{s.p95:.2f}")
        s = verification.sub_elements.get(name)
        if s is not None:
            table.add_row(
                Text(name, style="bold"),
                f"{assessment.sub_elements[name]:.2f}",
                Text(spread_text(s.mean, s.std), style="bold"),
                f"{s.p5:.2f}–{s.p95:.2f}",
                end_section=True,
            )
    return table


def scorecard_2026_renderables(
    assessment: Assessment2026, verification: VerificationReport | None = None
) -> list[RenderableType]:
    """Rich renderables for the terminal: the grids of each sub-element, the colour key, the points table and,
    with `verification`, the expected points after verification."""
    out: list[RenderableType] = [sub_element_grids(assessment, name, names) for name, names in panels(assessment)]
    out += [legend_text(), points_table(assessment)]
    if verification is not None:
        out.append(verification_table(assessment, verification))
    return out
