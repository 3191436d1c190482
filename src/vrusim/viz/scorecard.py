"""Euro NCAP scorecard of an Assessment: a PNG heat map (matplotlib, Agg) and Rich tables for the terminal.

One panel / table per group with tests: rows = scenario, lighting (and variant where the grid has one),
columns = VUT test speeds; each cell in its Euro NCAP colour (grey: not tested) showing "✓" when avoided,
the warning TTC for FCW-judged cells, else the relative impact speed in km/h.
"""

from __future__ import annotations

from pathlib import Path

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.colors import to_rgb
from matplotlib.figure import Figure
from rich import box
from rich.console import Group, RenderableType
from rich.table import Table
from rich.text import Text

from vrusim.io.atomic import write_atomically
from vrusim.ncap.assess import CRITERION_AVOIDANCE, CRITERION_FCW, AssessedTest, Assessment, GroupScore
from vrusim.ncap.scoring import POINTS_ENTRIES

COLOUR_HEX: dict[str, str] = {
    "green": "#3aa845",
    "yellow": "#f7d117",
    "orange": "#f39c12",
    "brown": "#8e5b2f",
    "red": "#d62b2b",
    "untested": "#cfcfcf",
}
"""Cell fill per Euro NCAP colour; "untested" for grid cells without a test."""
_LIGHT_TEXT = ("brown", "red")
CAPTION = (
    "Cells: relative impact speed (km/h; avoidance-only rows: impact speed); ✓ avoided; FCW cells: warning TTC;"
    " grey: not tested.\n"
    "Bands: 2026 protocol (v4.5.1 thresholds UNVERIFIED); split of points per scenario UNVERIFIED."
)

GROUP_TITLES = {
    "pedestrian": "Pedestrian",
    "cyclist": "Cyclist",
    "motorcyclist": "Motorcyclist",
    "escooter": "E-scooter (extension, not in the Euro NCAP total)",
}
_ORDER = {key: index for index, key in enumerate(POINTS_ENTRIES)}

Row = tuple[str, str, str]


def cell_text(test: AssessedTest, compact: bool = False) -> str:
    """What a cell shows: the warning TTC for FCW-judged cells, "✓" when avoided, else the relative impact
    speed — the impact speed for avoidance-only cells, which it decides (km/h; `compact`: whole km/h from 10
    up, for the terminal)."""
    if test.criterion == CRITERION_FCW:
        if test.warning_ttc_s is None:
            return "–" if compact else "no FCW"
        return f"{test.warning_ttc_s:.1f}" + ("s" if compact else " s")
    if not test.collided:
        return "✓"
    speed = test.impact_speed_kph if test.criterion == CRITERION_AVOIDANCE else test.relative_impact_speed_kph
    speed = speed or 0.0
    return f"{speed:.0f}" if compact and speed >= 10.0 else f"{speed:.1f}"


def row_label(row: Row) -> str:
    """ "CPNA-25 day" (plus the variant when there is one)."""
    scenario, lighting, variant = row
    return f"{scenario} {lighting}" + (f" {variant}" if variant else "")


def group_grid(tests: list[AssessedTest]) -> tuple[list[Row], list[float], dict[tuple[Row, float], AssessedTest]]:
    """Rows (table order, then variant), sorted speeds and the test of each (row, speed) cell."""
    cells = {((t.scenario, t.lighting, t.variant), t.vut_speed_kph): t for t in tests}
    rows = sorted({row for row, _ in cells}, key=lambda r: (_ORDER.get((r[0], r[1]), len(_ORDER)), r[2]))
    speeds = sorted({speed for _, speed in cells})
    return rows, speeds, cells


def panel_title(group: GroupScore) -> str:
    """Group name and points / cap (nominal points for an extension group)."""
    unit = "pts" if group.in_euro_ncap_total else "nominal pts"
    return f"{GROUP_TITLES.get(group.group, group.group)}: {group.score:.2f} / {group.max_points:g} {unit}"


def _groups_with_tests(assessment: Assessment) -> list[tuple[GroupScore, list[AssessedTest]]]:
    out = []
    for group in assessment.groups:
        tests = [t for t in assessment.tests if t.group == group.group]
        if tests:
            out.append((group, tests))
    return out


# ----------------------------------------------------------------------------------------------- PNG


def scorecard_figure(assessment: Assessment, dpi: float = 100.0) -> Figure:
    """The heat map as a matplotlib Figure on an Agg canvas (no pyplot state)."""
    panels = _groups_with_tests(assessment)
    grids = [group_grid(tests) for _, tests in panels]
    n_cols = max((len(speeds) for _, speeds, _ in grids), default=1)
    heights = [len(rows) + 1.5 for rows, _, _ in grids] or [1.0]
    fig = Figure(figsize=(3.0 + 0.75 * n_cols, 0.8 + 0.32 * sum(heights)), dpi=dpi, layout="constrained")
    FigureCanvasAgg(fig)
    title = f"Euro NCAP VRU AEB: {assessment.total:.2f} / {assessment.total_max:g} points"
    fig.suptitle(title, fontweight="bold")
    if not panels:
        fig.text(0.5, 0.5, "no tests", ha="center", va="center")
        return fig
    axes = fig.subplots(len(panels), 1, squeeze=False, gridspec_kw={"height_ratios": heights})[:, 0]
    for ax, (group, _), (rows, speeds, cells) in zip(axes, panels, grids, strict=True):
        image = [
            [to_rgb(COLOUR_HEX[cells[(row, s)].colour if (row, s) in cells else "untested"]) for s in speeds]
            for row in rows
        ]
        ax.imshow(image, aspect="auto", interpolation="nearest")
        for i, row in enumerate(rows):
            for j, speed in enumerate(speeds):
                test = cells.get((row, speed))
                if test is not None:
                    ink = "white" if test.colour in _LIGHT_TEXT else "black"
                    ax.text(j, i, cell_text(test), ha="center", va="center", fontsize=7, color=ink)
        ax.set_xticks(range(len(speeds)), [f"{s:g}" for s in speeds], fontsize=8)
        ax.set_yticks(range(len(rows)), [row_label(r) for r in rows], fontsize=8)
        ax.set_xticks([j - 0.5 for j in range(1, len(speeds))], minor=True)
        ax.set_yticks([i - 0.5 for i in range(1, len(rows))], minor=True)
        ax.grid(which="minor", color="white", linewidth=1.5)
        ax.tick_params(which="minor", length=0)
        ax.spines[:].set_visible(False)
        ax.set_xlim(-0.5, n_cols - 0.5)  # same cell width in every panel
        ax.set_xlabel("VUT test speed (km/h)", fontsize=8)
        ax.set_title(panel_title(group), fontsize=10, loc="left")
    fig.supxlabel(CAPTION, fontsize=8)
    return fig


def write_scorecard_png(assessment: Assessment, path: str | Path, dpi: float = 100.0) -> Path:
    """Render the heat map to a PNG at `path`, atomically (never a half-written file); return the path."""
    fig = scorecard_figure(assessment, dpi=dpi)
    return write_atomically(path, lambda temp: fig.savefig(temp, format="png", dpi=dpi), "scorecard")


# ----------------------------------------------------------------------------------------------- Rich


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
                ink = "white" if test.colour in _LIGHT_TEXT else "black"
                texts.append(Text(f" {cell_text(test, compact=True)} ", style=f"{ink} on {COLOUR_HEX[test.colour]}"))
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
    out: list[RenderableType] = [group_table(group, tests) for group, tests in _groups_with_tests(assessment)]
    out.append(totals_table(assessment))
    return out
