"""Euro NCAP scorecard of an Assessment as a PNG heat map (matplotlib, Agg); the terminal tables are in
`viz.scorecard_terminal`.

One panel / table per group with tests: rows = scenario, lighting (and variant where the grid has one),
columns = VUT test speeds; each cell in its Euro NCAP colour (grey: not tested) showing "✓" when avoided,
the warning TTC for FCW-judged cells, else the relative impact speed in km/h.
"""

from __future__ import annotations

from pathlib import Path

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.colors import to_rgb
from matplotlib.figure import Figure

from vrusim.io.atomic import write_atomically
from vrusim.ncap.assess import Assessment
from vrusim.viz.literal_text import drawing, literal_texts
from vrusim.viz.ncap_colours import COLOUR_HEX, ink
from vrusim.viz.scorecard_cells import CAPTION, cell_text, group_grid, groups_with_tests, panel_title, row_label


def scorecard_figure(assessment: Assessment, dpi: float = 100.0) -> Figure:
    """The heat map as a matplotlib Figure on an Agg canvas (no pyplot state)."""
    panels = groups_with_tests(assessment)
    grids = [group_grid(tests) for _, tests in panels]
    n_cols = max((len(speeds) for _, speeds, _ in grids), default=1)
    heights = [len(rows) + 1.5 for rows, _, _ in grids] or [1.0]
    fig = Figure(figsize=(3.0 + 0.75 * n_cols, 0.8 + 0.32 * sum(heights)), dpi=dpi, layout="constrained")
    FigureCanvasAgg(fig)
    title = f"Euro NCAP VRU AEB: {assessment.total:.2f} / {assessment.total_max:g} points"
    fig.suptitle(title, fontweight="bold")
    if not panels:
        fig.text(0.5, 0.5, "no tests", ha="center", va="center")
        return literal_texts(fig)
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
                    ax.text(j, i, cell_text(test), ha="center", va="center", fontsize=7, color=ink(test.colour))
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
    return literal_texts(fig)


def write_scorecard_png(assessment: Assessment, path: str | Path, dpi: float = 100.0) -> Path:
    """Render the heat map to a PNG at `path`, atomically (never a half-written file); return the path."""
    fig = scorecard_figure(assessment, dpi=dpi)
    with drawing(fig):
        return write_atomically(path, lambda temp: fig.savefig(temp, format="png", dpi=dpi), "scorecard")
