"""The picture of one run that `vrusim run --plot` writes: key-event snapshots above the time series."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from vrusim.viz.figure_io import write_figure
from vrusim.viz.literal_text import literal_texts
from vrusim.viz.recording import Recording
from vrusim.viz.snapshots import draw_snapshots, snapshot_size_in
from vrusim.viz.timeseries import draw_timeseries

TIMESERIES_HEIGHT_IN = 8.0
"""Height of the time-series part of a run figure, inches."""


def run_figure(recordings: Sequence[Recording], dpi: float = 100.0) -> Figure:
    """One figure: the snapshot rows (one per recording, at its key moments) on top, the time series below."""
    recordings = list(recordings)
    width, snap_height = snapshot_size_in(recordings)
    fig = Figure(figsize=(width, snap_height + TIMESERIES_HEIGHT_IN), dpi=dpi, layout="constrained")
    FigureCanvasAgg(fig)
    top, bottom = fig.subfigures(2, 1, height_ratios=[snap_height, TIMESERIES_HEIGHT_IN])
    draw_snapshots(top, recordings)
    draw_timeseries(bottom, recordings)
    bottom.suptitle("")
    return literal_texts(fig)


def write_run_figure(recordings: Sequence[Recording], path: str | Path, dpi: float = 100.0) -> Path:
    """`run_figure` saved to `path` (.png, .svg or .pdf), atomically."""
    return write_figure(run_figure(recordings, dpi), path, dpi)
