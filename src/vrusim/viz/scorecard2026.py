"""Euro NCAP 2026 scorecard of an Assessment2026 as a PNG (matplotlib, Agg); the terminal tables are in
`viz.scorecard2026_terminal`.

One panel per official scenario, grouped by sub-element, laid out as FC26 / LSC26 print the grids: rows VUT
speed (then turn or FCW; LSC: distance or gap), columns impact location (100 % first) or target speed. Each cell
in its colour; extended-range cells hatched (PNG) or marked "e" (terminal); grey where the grid has no test.
Panel titles: points / max points; the figure title: the sub-element totals.
"""

from __future__ import annotations

from pathlib import Path

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.patches import Patch, Rectangle

from vrusim.io.atomic import write_atomically
from vrusim.ncap.rating2026 import Assessment2026
from vrusim.ncap.rating2026 import tables as t
from vrusim.ncap.verification import VerificationReport
from vrusim.viz.literal_text import drawing, literal_texts
from vrusim.viz.ncap_colours import COLOUR_HEX, ink
from vrusim.viz.scorecard2026_cells import (
    AXIS_TITLES,
    compact_column,
    compact_row,
    grid_cells,
    kpi_text,
    panel_title,
    panels,
    probability_text,
    sub_element_max_points,
)

EXTENDED_HATCH = "///"
"""Hatch of extended-range cells in the PNG (a transparent patch over the cell, gid TEST_ID + EXTENDED_SUFFIX)."""
EXTENDED_SUFFIX = ":extended"
HATCH_INK = (0.0, 0.0, 0.0, 0.4)
PANELS_PER_ROW = 4
CELL_ASPECT = 0.5
"""Cell height / width in the PNG."""
CAPTION_2026 = (
    "Rows: VUT speed (FCW rows last; LSC: distance / gap); columns: impact location (100 % first) or target speed.\n"
    "Cells: Vrel_impact / Vimpact (km/h), ✓ no impact, FCW rows: warning TTC (s); hatched: extended range; grey: no "
    "test. Points before verification (FC26 §5.3, LSC26)."
)
CAPTION_VERIFIED = (
    "Rows: VUT speed (FCW rows last; LSC: distance / gap); columns: impact location (100 % first) or target speed.\n"
    "Cells: verification pass probability (%), blank: not a verification candidate (predicted red or corner case); "
    "hatched: extended range; grey: no test."
)


def _draw_panel(ax, assessment: Assessment2026, scenario: str, verification: VerificationReport | None) -> None:
    grid, cells = grid_cells(assessment, scenario)
    for i, row in enumerate(grid.rows):
        for j, column in enumerate(grid.columns):
            cell = cells.get((row, column))
            colour = cell.colour if cell is not None else "untested"
            extended = cell is not None and cell.range == "extended"
            fill = Rectangle(
                (j - 0.5, i - 0.5),
                1.0,
                1.0,
                facecolor=COLOUR_HEX[colour],
                edgecolor="white",
                linewidth=1.5,
                gid=cell.test_id if cell is not None else f"untested:{row}|{column}",
            )
            ax.add_patch(fill)
            if extended:
                hatch = Rectangle(
                    (j - 0.45, i - 0.45),
                    0.9,
                    0.9,
                    fill=False,
                    edgecolor=HATCH_INK,
                    linewidth=0.0,
                    hatch=EXTENDED_HATCH,
                    gid=f"{cell.test_id}{EXTENDED_SUFFIX}",
                )
                ax.add_patch(hatch)
            if cell is not None:
                text = probability_text(cell, verification) if verification is not None else kpi_text(cell)
                ax.text(j, i, text, ha="center", va="center", fontsize=6.5, color=ink(cell.colour))
    ax.set_xlim(-0.5, len(grid.columns) - 0.5)
    ax.set_ylim(len(grid.rows) - 0.5, -0.5)
    ax.set_aspect(CELL_ASPECT, adjustable="box")
    ax.set_xticks(range(len(grid.columns)), [compact_column(c) for c in grid.columns], fontsize=7)
    ax.set_yticks(range(len(grid.rows)), [compact_row(r) for r in grid.rows], fontsize=7)
    ax.tick_params(length=0)
    ax.spines[:].set_visible(False)
    unit = "%" if grid.column_axis == "impact_location" else "km/h"
    ax.set_xlabel(f"{AXIS_TITLES.get(grid.column_axis, grid.column_axis).split(' (')[0]} ({unit})", fontsize=7)
    ax.set_title(panel_title(assessment, scenario), fontsize=8.5, loc="left")


def figure_title(assessment: Assessment2026) -> str:
    """The sub-element totals (points / max, before verification), two per line."""
    totals = [
        f"{name} {assessment.sub_elements[name]:.2f} / {sub_element_max_points(name):g}"
        for name, _ in panels(assessment)
    ]
    lines = ["   ·   ".join(totals[k : k + 2]) for k in range(0, len(totals), 2)]
    return "\n".join(["Euro NCAP 2026 VRU crash avoidance, points before verification", *lines])


def scorecard_2026_figure(
    assessment: Assessment2026, dpi: float = 100.0, verification: VerificationReport | None = None
) -> Figure:
    """The 2026 scorecard as a matplotlib Figure on an Agg canvas (no pyplot state): a block per sub-element,
    a panel per scenario; cell patches carry their test id as `gid` (untested: "untested:ROW|COLUMN").
    `verification`: show each cell's pass probability instead of its KPI."""
    groups = panels(assessment)
    layout = [[names[k : k + PANELS_PER_ROW] for k in range(0, len(names), PANELS_PER_ROW)] for _, names in groups]
    row_heights = [
        [max(len(assessment.grid(s).rows) for s in line) + 2.5 for line in lines] for lines in layout
    ]  # grid rows + title and axis labels
    block_heights = [sum(h) + 1.2 for h in row_heights] or [1.0]
    n_cols = max((len(assessment.grid(s).columns) for _, names in groups for s in names), default=1)
    title = figure_title(assessment)
    top_in = 0.3 + 0.22 * title.count("\n")
    fig = Figure(
        figsize=(2.0 + PANELS_PER_ROW * (1.0 + 0.42 * n_cols), top_in + 0.9 + 0.2 * sum(block_heights)),
        dpi=dpi,
        layout="constrained",
    )
    FigureCanvasAgg(fig)
    fig.suptitle(title, fontweight="bold", fontsize=10)
    if not groups:
        fig.text(0.5, 0.5, "no scenarios", ha="center", va="center")
        return literal_texts(fig)
    blocks = fig.subfigures(len(groups), 1, height_ratios=block_heights, squeeze=False)[:, 0]
    for block, (name, _), lines, heights in zip(blocks, groups, layout, row_heights, strict=True):
        block.suptitle(name, fontsize=9.5, x=0.0, ha="left", fontweight="bold")
        axes = block.subplots(len(lines), PANELS_PER_ROW, squeeze=False, gridspec_kw={"height_ratios": heights})
        for line, ax_row in zip(lines, axes, strict=True):
            for k, ax in enumerate(ax_row):
                if k < len(line):
                    _draw_panel(ax, assessment, line[k], verification)
                else:
                    ax.set_axis_off()
    legend = [Patch(facecolor=COLOUR_HEX[c], label=c) for c in (*t.COLOURS, "untested")]
    legend.append(Patch(facecolor="white", edgecolor=HATCH_INK, hatch=EXTENDED_HATCH, label="extended range"))
    caption = CAPTION_VERIFIED if verification is not None else CAPTION_2026
    fig.legend(
        handles=legend,
        loc="outside lower center",
        ncols=len(legend),
        fontsize=7,
        frameon=False,
        title=caption,
        title_fontsize=7,
    )
    return literal_texts(fig)


def write_scorecard_2026_png(
    assessment: Assessment2026, path: str | Path, dpi: float = 100.0, verification: VerificationReport | None = None
) -> Path:
    """Render the 2026 scorecard to a PNG at `path`, atomically; return the path."""
    fig = scorecard_2026_figure(assessment, dpi=dpi, verification=verification)
    with drawing(fig):
        return write_atomically(path, lambda temp: fig.savefig(temp, format="png", dpi=dpi), "scorecard")
