"""Multi-panel snapshot figures like the paper's Figs. 6-8: one row per recording (e.g. V2X off / on), one
column per moment — chosen times, or each row's start and key events (first perception, brake onset, impact
or closest approach; events at the same time share a panel)."""

from __future__ import annotations

import string
from collections.abc import Sequence

from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure, SubFigure

from vrusim.metrics.outcome import outcome_of
from vrusim.viz.literal_text import literal_texts
from vrusim.viz.recording import Recording
from vrusim.viz.scene import SceneArtists, legend_handles, view_window
from vrusim.viz.style import recording_labels


def panel_moments(recording: Recording, at_s: Sequence[float] | None = None) -> list[tuple[str, float]]:
    """(title label, t_s) of a row's panels: the given times, or the recording's key moments."""
    if at_s is None:
        return recording.key_moments()
    return [("", float(t)) for t in at_s]


def panel_title(letter: str, label: str, t_s: float) -> str:
    """ "(a) brake onset, t = 3.06 s" (just the time when there is no label)."""
    return f"({letter}) {label}, t = {t_s:.2f} s" if label else f"({letter}) t = {t_s:.2f} s"


def snapshot_size_in(
    recordings: Sequence[Recording], at_s: Sequence[float] | None = None, panel_width_in: float = 4.2
) -> tuple[float, float]:
    """(width, height) in inches that fits the panels of `snapshot_figure` at their equal aspect."""
    n_cols = max(1, *(len(panel_moments(r, at_s)) for r in recordings))
    window = view_window(list(recordings))
    panel_height = panel_width_in * window.height_m / window.width_m + 0.45
    return panel_width_in * n_cols + 0.5, panel_height * len(recordings) + 1.1


def snapshot_figure(
    recordings: Sequence[Recording],
    at_s: Sequence[float] | None = None,
    labels: Sequence[str] | None = None,
    panel_width_in: float = 4.2,
    dpi: float = 100.0,
) -> Figure:
    """Rows = `recordings` (labelled "V2X off" / "V2X on" or `labels`), columns = `at_s` times, or when None
    each row's key moments; all panels share one view window so positions compare across the figure.

    A panel at a key event shows the trace sample nearest to it; at a chosen time, the last sample at or
    before it. Panel titles give the letter, the event and the time.
    """
    recordings = list(recordings)
    if not recordings:
        raise ValueError("snapshot_figure needs at least one recording")
    fig = Figure(figsize=snapshot_size_in(recordings, at_s, panel_width_in), dpi=dpi, layout="constrained")
    FigureCanvasAgg(fig)
    draw_snapshots(fig, recordings, at_s, labels)
    return literal_texts(fig)


def draw_snapshots(
    fig: Figure | SubFigure,
    recordings: Sequence[Recording],
    at_s: Sequence[float] | None = None,
    labels: Sequence[str] | None = None,
) -> list[Axes]:
    """Draw the snapshot panels, title and legend of `snapshot_figure` on `fig`; return the visible axes."""
    recordings = list(recordings)
    labels = list(labels) if labels is not None else recording_labels(recordings)
    moments = [panel_moments(r, at_s) for r in recordings]
    n_cols = max(1, *(len(m) for m in moments))
    window = view_window(recordings)
    axes = fig.subplots(len(recordings), n_cols, squeeze=False)
    letters = iter(string.ascii_lowercase * 4)
    shown: list[Axes] = []
    for row, (recording, row_moments, label) in enumerate(zip(recordings, moments, labels, strict=True)):
        for col in range(n_cols):
            ax = axes[row, col]
            if col >= len(row_moments):
                ax.set_visible(False)
                continue
            event, t_s = row_moments[col]
            scene = SceneArtists(ax, recording, window)
            scene.update(recording.nearest_index(t_s) if at_s is None else recording.index_at(t_s))
            ax.set_title(panel_title(next(letters), event, t_s), fontsize=9, loc="left")
            if row < len(recordings) - 1:
                ax.set_xlabel("")
            if col > 0:
                ax.set_ylabel("")
            else:
                ax.set_ylabel(f"{label}: {outcome_of(recording.summary)}\ny (m)", fontsize=9)
            shown.append(ax)
    fig.suptitle(_title(recordings), fontsize=10, fontweight="bold")
    handles, names = legend_handles(recordings)
    fig.legend(handles, names, loc="outside lower center", ncol=min(len(handles), 7), fontsize=8, frameon=False)
    return shown


def _title(recordings: Sequence[Recording]) -> str:
    """The scenario name and description, one line per distinct scenario."""
    scenarios = {r.scenario.name: r.scenario.description for r in recordings}
    return "\n".join(f"{name}: {text}" if text else name for name, text in scenarios.items())
