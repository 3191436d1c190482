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

CELL_WIDTH = 4
"""Characters per grid cell: a coloured block of 3 and a space."""
GRID_GAP = 3
"""Characters between two grids side by side."""


def _centred(text: str, width: int) -> str:
    """`text` centred in `width` characters (as Rich centred these cells: the odd space on the left)."""
    excess = width - len(text)
    return " " * (excess - excess // 2) + text + " " * (excess // 2)


def _grid_lines(assessment: Assessment2026, scenario: str) -> list[Text]:
    """A scenario's title (points / max) and compact grid as lines: one coloured block per cell ("e": extended
    range, "·": no test). Built as fixed-width text, not a Rich table: the terminal scorecard draws 20-odd grids,
    and measuring and laying them out as nested tables took 113 ms of `vrusim ncap`'s output, text 28 ms."""
    grid, cells = grid_cells(assessment, scenario)
    corner = "IL%" if grid.column_axis == "impact_location" else "tgt"
    labels = [compact_row(row) + " " for row in grid.rows]
    first = max(len(corner), *(len(label) for label in labels))
    headers = [compact_column(column).rjust(3) for column in grid.columns]
    widths = [max(CELL_WIDTH, len(header)) for header in headers]
    title = f"{scenario} {assessment.scenarios[scenario].total:.2f}/{scenario_max_points(scenario):g}"
    header_line = corner.ljust(first) + "".join(h.ljust(w) for h, w in zip(headers, widths, strict=True))
    lines = [Text(title, style="bold"), Text(header_line, style="bold")]
    for row, label in zip(grid.rows, labels, strict=True):
        line = Text(label.ljust(first))
        for column, width in zip(grid.columns, widths, strict=True):
            cell = cells.get((row, column))
            if cell is None:
                line.append(_centred(" · ", width), style="dim")
            else:
                mark = " e " if cell.range == "extended" else "   "
                line.append(_centred(mark, width), style=f"{ink(cell.colour)} on {COLOUR_HEX[cell.colour]}")
        lines.append(line)
    return lines


def _joined(lines: list[Text]) -> Text:
    """Lines as one Text that Rich neither wraps nor justifies."""
    return Text("\n", no_wrap=True, overflow="ignore").join(lines)


def grid_table(assessment: Assessment2026, scenario: str) -> Text:
    """A scenario's title (points / max) and compact grid (`_grid_lines`)."""
    return _joined(_grid_lines(assessment, scenario))


def _padded(line: Text, width: int) -> Text:
    return Text.assemble(line, " " * (width - line.cell_len))


def sub_element_grids(assessment: Assessment2026, name: str, scenarios: list[str]) -> Group:
    """A sub-element's title and its scenario grids, two side by side (fits 80 columns), tops aligned."""
    blocks = [_grid_lines(assessment, scenario) for scenario in scenarios]
    widths = [max((line.cell_len for block in blocks[k::2] for line in block), default=0) for k in (0, 1)]
    lines: list[Text] = []
    for k in range(0, len(blocks), 2):
        left, right = blocks[k], blocks[k + 1] if k + 1 < len(blocks) else []
        for i in range(max(len(left), len(right))):
            cell_left = left[i] if i < len(left) else Text()
            cell_right = right[i] if i < len(right) else Text()
            lines.append(Text.assemble(_padded(cell_left, widths[0]), " " * GRID_GAP, _padded(cell_right, widths[1])))
    return Group(Text(sub_element_title(assessment, name), style="bold underline"), _joined(lines))


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
