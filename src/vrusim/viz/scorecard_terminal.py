"""Euro NCAP 2023 scorecard for the terminal (Rich): one colour grid per group with tests, then the totals."""

from __future__ import annotations

from rich import box
from rich.console import Group, RenderableType
from rich.table import Table
from rich.text import Text

from vrusim.ncap.assess import AssessedTest, Assessment, GroupScore
from vrusim.viz.ncap_colours import COLOUR_HEX, ink
from vrusim.viz.scorecard_cells import GROUP_TITLES, cell_text, group_grid, groups_with_tests, panel_title, row_label


def group_table(group: GroupScore, tests: list[AssessedTest]) -> Group:
    """One group's title (points / cap) and colour grid: rows scenarios, columns test speeds."""
    rows, speeds, cells = group_grid(tests)
    table = Table(box=None, padding=(0, 0), header_style="bold underline")  # no dividers: fits 80 columns
    table.add_column("Scenario ")  # wraps ("CBNAO-50\nday") rather than cut at 80 columns
    for speed in speeds:
        table.add_column(f" {speed:g} ", justify="center", no_wrap=True)
    for row in rows:
        texts = []
        for speed in speeds:
            test = cells.get((row, speed))
            if test is None:
                texts.append(Text("·", style="dim"))
            else:
                style = f"{ink(test.colour)} on {COLOUR_HEX[test.colour]}"
                texts.append(Text(f" {cell_text(test, compact=True)} ", style=style))
        table.add_row(row_label(row), *texts)
    return Group(Text(panel_title(group), style="bold"), table)


def totals_table(assessment: Assessment) -> Table:
    """Points per group and the Euro NCAP total; extension groups are listed but not added."""
    table = Table(title="Euro NCAP VRU AEB points", box=box.SIMPLE_HEAD, title_justify="left")
    table.add_column("Group")
    table.add_column("Points", justify="right")
    table.add_column("Max", justify="right")
    table.add_column("In total", justify="center")
    table.add_column("Not assessed")
    for group in assessment.groups:
        table.add_row(
            GROUP_TITLES.get(group.group, group.group),
            f"{group.score:.2f}",
            f"{group.max_points:g}",
            "yes" if group.in_euro_ncap_total else "no",
            ", ".join(group.not_assessed) or "—",
        )
    table.add_section()
    table.add_row("[bold]Total[/]", f"[bold]{assessment.total:.2f}[/]", f"{assessment.total_max:g}", "", "")
    return table


def scorecard_renderables(assessment: Assessment) -> list[RenderableType]:
    """Rich renderables for the terminal: one colour grid per group with tests, then the totals table."""
    out: list[RenderableType] = [group_table(group, tests) for group, tests in groups_with_tests(assessment)]
    out.append(totals_table(assessment))
    return out
