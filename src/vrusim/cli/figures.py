"""Figure options of the commands: `vrusim run --plot/--animate` and `vrusim paper --figures DIR`.

Each option's path is checked before anything is simulated; a bad one is a UserInputError naming the option.
"""

from __future__ import annotations

import os
from pathlib import Path

from vrusim.cli.output import named_errors
from vrusim.errors import UserInputError
from vrusim.io.paths import check_output_folder, for_option, new_folder

PAPER_FIGURE_DPI = 110.0
"""Resolution of the `paper --figures` PNGs, dots per inch."""


def check_run_outputs(plot: Path | None, animate: Path | None) -> None:
    """Fail (naming --plot / --animate) unless each given path has a known suffix and a writable folder."""
    from vrusim.io.paths import check_output_file

    if plot is not None:
        from vrusim.viz.figure_io import check_figure_path

        check_output_file(plot, "--plot")
        with named_errors("--plot"):
            check_figure_path(plot)
    if animate is not None:
        from vrusim.viz.animate import check_animation_path  # imports matplotlib: only when asked for

        check_output_file(animate, "--animate")
        with named_errors("--animate"):
            check_animation_path(animate)


def write_run_outputs(run, scenario, plot: Path | None, animate: Path | None) -> list[str]:
    """Write the run figure and / or the animation of a traced one-variant run of `scenario`; return what was
    written."""
    from vrusim.viz.recording import recordings_of

    recordings = recordings_of(run, [scenario])
    written = []
    if plot is not None:
        from vrusim.viz.runplot import write_run_figure

        with named_errors("--plot"):
            write_run_figure(recordings, plot)
        written.append(f"Figure written to {plot}.")
    if animate is not None:
        from vrusim.viz.animate import write_animation

        with named_errors("--animate"):
            write_animation(recordings[0], animate)
        written.append(f"Animation written to {animate}.")
    return written


def check_figures_dir(directory: Path) -> Path:
    """--figures DIR: an existing writable folder, or a new one whose parent exists and is writable."""
    check_output_folder(directory, "--figures")
    if directory.exists() and not directory.is_dir():
        raise UserInputError(f"--figures: {directory} is not a folder")
    folder = directory if directory.is_dir() else directory.parent
    if not folder.is_dir():
        raise UserInputError(f"--figures: folder {folder} does not exist")
    if not os.access(folder, os.W_OK):
        raise UserInputError(f"--figures: folder {folder} is not writable")
    return directory


def paper_figure_names(case_key: str) -> tuple[str, str]:
    """File names of a case's snapshot and time-series figures."""
    return f"{case_key}_snapshots.png", f"{case_key}_timeseries.png"


def write_paper_figures(directory: Path, dpi: float = PAPER_FIGURE_DPI) -> list[Path]:
    """Simulate the paper's six runs traced; write per case its snapshot figure (rows V2X off / on, columns
    at the key moments) and its time-series figure, all six files or none."""
    from vrusim.io.atomic import write_together
    from vrusim.paper.cases import CASES, paper_scenarios
    from vrusim.viz.recording import record
    from vrusim.viz.snapshots import snapshot_figure
    from vrusim.viz.timeseries import timeseries_figure

    runs = paper_scenarios()
    recordings = record([scenario for _, _, scenario in runs])
    targets = []
    for case in CASES:
        pair = [rec for (c, _, _), rec in zip(runs, recordings, strict=True) if c.key == case.key]
        snapshots, timeseries = paper_figure_names(case.key)
        for name, fig in ((snapshots, snapshot_figure(pair)), (timeseries, timeseries_figure(pair))):
            targets.append((directory / name, _saver(fig, dpi), "figure"))
    with new_folder(directory, "--figures"), for_option("--figures"):
        return write_together(targets)


def _saver(fig, dpi: float):
    from vrusim.viz.literal_text import drawing

    def save(temp) -> None:
        with drawing(fig):
            fig.savefig(temp, format="png", dpi=dpi)

    return save
