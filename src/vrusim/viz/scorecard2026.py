"""Euro NCAP 2026 scorecard of an Assessment2026: a PNG (matplotlib, Agg) and Rich tables for the terminal.

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
from rich import box
from rich.console import Group, RenderableType
from rich.table import Table
from rich.text import Text

from vrusim.io.atomic import write_atomically
from vrusim.ncap.rating2026 import Assessment2026, CellResult2026, ScenarioGrid
from vrusim.ncap.rating2026 import tables as t
from vrusim.ncap.verification import VerificationReport
from vrusim.viz.scorecard import COLOUR_HEX

LIGHT_TEXT = ("brown", "red")
"""Colours whose cells take white text."""
EXTENDED_HATCH = "///"
"""Hatch of extended-range cells in the PNG (a transparent patch over the cell, gid TEST_ID + EXTENDED_SUFFIX)."""
EXTENDED_SUFFIX = ":extended"
HATCH_INK = (0.0, 0.0, 0.0, 0.4)
PANELS_PER_ROW = 4
CELL_ASPECT = 0.5
"""Cell height / width in the PNG."""
AXIS_TITLES = {"impact_location": "impact location", "target_speed": "target speed (km/h)"}
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

Key = tuple[str, str]
"""(row label, column label) of a grid cell."""


# ----------------------------------------------------------------------------------------------- shared


def scenario_max_points(scenario: str) -> float:
    """Maximum points of a scenario: standard + extended + robustness (t.TOTAL_POINTS)."""
    return sum(t.TOTAL_POINTS[scenario].values())


def sub_element_max_points(name: str) -> float:
    """Maximum points of a sub-element's VRU scenarios (20 and 10 for the whole Pedestrian & Cyclist ones)."""
    return sum(scenario_max_points(s) for s in t.SUB_ELEMENTS[name])


def panels(assessment: Assessment2026) -> list[tuple[str, list[str]]]:
    """(sub-element, its assessed scenarios in table order) for every sub-element with a scenario."""
    out = []
    for name, members in t.SUB_ELEMENTS.items():
        present = [s for s in members if s in assessment.scenarios]
        if present:
            out.append((name, present))
    return out


def grid_cells(assessment: Assessment2026, scenario: str) -> tuple[ScenarioGrid, dict[Key, CellResult2026]]:
    """The scenario's grid and its cell at each (row label, column label) (robustness-layer rows left out)."""
    cells = {(c.row_label, c.column_label): c for c in assessment.cells_of(scenario) if c.range != "robustness"}
    return assessment.grid(scenario), cells


def panel_title(assessment: Assessment2026, scenario: str) -> str:
    """ "CPNA day: 0.61 / 0.69" (points / max points)."""
    return f"{scenario}: {assessment.scenarios[scenario].total:.2f} / {scenario_max_points(scenario):g}"


def sub_element_title(assessment: Assessment2026, name: str) -> str:
    """ "FC Pedestrian & Cyclist: 14.11 / 20 pts" (points of the assessed scenarios / max of all)."""
    return f"{name}: {assessment.sub_elements[name]:.2f} / {sub_element_max_points(name):g} pts"


def compact_row(label: str) -> str:
    """A grid row label for narrow spaces: "10 km/h farside" -> "10 fs", "50 km/h FCW" -> "50 FCW"."""
    return label.replace(" km/h", "").replace("farside", "fs").replace("nearside", "ns")


def compact_column(label: str) -> str:
    """A grid column label without its unit: "100%" -> "100", "30 km/h" -> "30"."""
    return label.replace(" km/h", "").rstrip("%")


def kpi_text(cell: CellResult2026) -> str:
    """What a cell shows without verification: warning TTC (s) for FCW-judged cells, "✓" without impact, else the
    KPI in whole km/h (one decimal below 10); "hit" for a contact at 0 km/h (CBDA: a cyclist into the door of the
    parked VUT)."""
    if cell.criterion == t.WARNING:
        return "–" if cell.kpi is None else f"{cell.kpi:.1f}"
    if not cell.kpi:
        return "hit" if cell.colour == "red" else "✓"
    return f"{cell.kpi:.0f}" if cell.kpi >= 10.0 else f"{cell.kpi:.1f}"


def probability_text(cell: CellResult2026, verification: VerificationReport) -> str:
    """A cell's verification pass probability in whole percent, "" when it is not a verification candidate."""
    p = verification.pass_probability.get(cell.test_id)
    return "" if p is None else f"{100 * p:.0f}"


def ink(colour: str) -> str:
    """Text colour on a cell of `colour`."""
    return "white" if colour in LIGHT_TEXT else "black"


# ----------------------------------------------------------------------------------------------- PNG


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
        return fig
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
    return fig


def write_scorecard_2026_png(
    assessment: Assessment2026, path: str | Path, dpi: float = 100.0, verification: VerificationReport | None = None
) -> Path:
    """Render the 2026 scorecard to a PNG at `path`, atomically; return the path."""
    fig = scorecard_2026_figure(assessment, dpi=dpi, verification=verification)
    return write_atomically(path, lambda temp: fig.savefig(temp, format="png", dpi=dpi), "scorecard")


# ----------------------------------------------------------------------------------------------- Rich


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
