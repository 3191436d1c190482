"""Time-series figure of one or more recordings (e.g. V2X off / on overlaid), stacked axes sharing t:

speed (ego solid, VRU dashed), acceleration (actual solid, planner command dotted), jerk, planner state as a
coloured band (one row per recording), TTC and gap (ego–VRU clearance), with vertical key-event markers.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence

import numpy as np
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure, SubFigure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from vrusim.viz import style
from vrusim.viz.literal_text import literal_texts
from vrusim.viz.recording import KEY_EVENT_LABELS, Recording
from vrusim.viz.style import recording_labels

TTC_CAP_S = 10.0
"""Top of the TTC axis, s (larger and infinite TTC are off the chart)."""
GAP_CAP_M = 30.0
"""Top of the gap axis when gaps are larger, m (the close calls are what matters)."""
BAND_HEIGHT = 0.8
"""Height of a recording's planner-state band, in rows."""


def mode_spans(recording: Recording) -> Iterator[tuple[float, float, int]]:
    """(start_s, stop_s, mode index) of each run of one planner mode, by the time the mode was decided."""
    t, mode = recording.decisions("planner_mode")
    if len(t) == 0:
        return
    end = float(recording.t_s[-1])
    change = np.flatnonzero(np.diff(mode)) + 1
    starts = np.concatenate([[0], change])
    stops = np.concatenate([change, [len(mode)]])
    for a, b in zip(starts, stops, strict=True):
        yield float(t[a]), float(t[b]) if b < len(t) else end, int(mode[a])


def jerk(recording: Recording) -> tuple[np.ndarray, np.ndarray]:
    """Ego jerk (t_s [T-1], m/s^3): finite difference of the achieved acceleration."""
    t, a = recording.t_s, recording.trace["ego_accel_mps2"]
    return t[1:], np.diff(a) / np.diff(t)


def _finite_below(values: np.ndarray, cap: float) -> np.ndarray:
    out = np.asarray(values, dtype=float).copy()
    out[~np.isfinite(out) | (out > cap * 1.5)] = np.nan
    return out


def timeseries_figure(
    recordings: Sequence[Recording], labels: Sequence[str] | None = None, width_in: float = 8.0, dpi: float = 100.0
) -> Figure:
    """Stacked time series of `recordings` overlaid (colour per recording, legend labels "V2X off" / "V2X on"
    or `labels`); the planner-state band axis is `fig.axes[3]`, one row per recording from the top."""
    recordings = list(recordings)
    if not recordings:
        raise ValueError("timeseries_figure needs at least one recording")
    fig = Figure(figsize=(width_in, 9.0 + 0.3 * len(recordings)), dpi=dpi, layout="constrained")
    FigureCanvasAgg(fig)
    draw_timeseries(fig, recordings, labels)
    return literal_texts(fig)


def draw_timeseries(
    fig: Figure | SubFigure, recordings: Sequence[Recording], labels: Sequence[str] | None = None
) -> list[Axes]:
    """Draw the six stacked axes, title and legend of `timeseries_figure` on `fig`; return the axes."""
    recordings = list(recordings)
    labels = list(labels) if labels is not None else recording_labels(recordings)
    n = len(recordings)
    band_ratio = 0.35 + 0.25 * n
    axes = fig.subplots(6, 1, sharex=True, gridspec_kw={"height_ratios": [1.2, 1.1, 0.9, band_ratio, 0.9, 0.9]})
    ax_speed, ax_accel, ax_jerk, ax_band, ax_ttc, ax_gap = axes
    colours = [style.RECORDING_COLOURS[i % len(style.RECORDING_COLOURS)] for i in range(n)]
    modes_seen: dict[str, str] = {}
    for row, (rec, colour) in enumerate(zip(recordings, colours, strict=True)):
        t, trace = rec.t_s, rec.trace
        ax_speed.plot(t, trace["ego_speed_mps"], color=colour, lw=1.6)
        for k in range(len(rec.scenario.vrus)):
            ax_speed.plot(t, trace["vru_speed_mps"][:, k], color=colour, lw=1.1, ls="--")
        ax_accel.plot(t, trace["ego_accel_mps2"], color=colour, lw=1.4)
        t_cmd, command = rec.decisions("ego_command_mps2")
        ax_accel.step(t_cmd, command, where="post", color=colour, lw=1.0, ls=":")
        ax_jerk.plot(*jerk(rec), color=colour, lw=1.0)
        ax_ttc.plot(t, _finite_below(trace["ttc_s"], TTC_CAP_S), color=colour, lw=1.4)
        ax_gap.plot(t, trace["clearance_m"], color=colour, lw=1.4)
        y = n - 1 - row
        for start, stop, mode in mode_spans(rec):
            name = rec.mode_names[mode] if mode < len(rec.mode_names) else str(mode)
            fill = style.mode_colour(name, mode)
            modes_seen.setdefault(name, fill)
            ax_band.broken_barh([(start, stop - start)], (y - BAND_HEIGHT / 2, BAND_HEIGHT), facecolors=fill)
        _mark_events(axes, ax_band, ax_speed, rec, y, colour)
    end = max(float(r.t_s[-1]) for r in recordings)
    _decorate(axes, labels, end)
    ax_jerk.set_ylim(*_jerk_limits(recordings))
    gap_top = max(float(np.nanmax(r.trace["clearance_m"])) for r in recordings)
    ax_gap.set_ylim(0, min(gap_top * 1.05, GAP_CAP_M) if gap_top > 0 else 1.0)
    fig.suptitle(" / ".join(dict.fromkeys(r.scenario.name for r in recordings)), fontsize=10, fontweight="bold")
    fig.legend(*_legend(recordings, labels, colours, modes_seen), loc="outside lower center", ncol=5, fontsize=8)
    return list(axes)


def _jerk_limits(recordings: Sequence[Recording]) -> tuple[float, float]:
    """Jerk axis range, m/s^3: 1.5 x the largest jerk limit of the scenarios, else of the 99th-percentile jerk;
    the step to standstill (acceleration snapping to 0) would otherwise flatten everything else."""
    limits = [r.scenario.ego.max_jerk_mps3 for r in recordings if r.scenario.ego.max_jerk_mps3 is not None]
    if limits:
        top = 1.5 * max(limits)
    else:
        top = 1.2 * max(float(np.percentile(np.abs(jerk(r)[1]), 99)) if len(r.t_s) > 1 else 0.0 for r in recordings)
    top = max(top, 1.0)
    return -top, top


def _mark_events(axes, ax_band: Axes, ax_speed: Axes, rec: Recording, y: int, colour: str) -> None:
    """Vertical event lines on every axis, a marker on the recording's band row and on its ego speed."""
    for name, t_event in rec.events_s.items():
        event_colour, line = style.EVENT_STYLES[name]
        for ax in axes:
            if ax is not ax_band:
                ax.axvline(t_event, color=event_colour, ls=line, lw=1.0, alpha=0.8, zorder=0.5)
        ax_band.plot([t_event], [y], marker="|", ms=14, mew=2.2, color=event_colour, zorder=3)
        speed = float(np.interp(t_event, rec.t_s, rec.trace["ego_speed_mps"]))
        ax_speed.plot([t_event], [speed], marker="o", ms=5, mfc=event_colour, mec=colour, zorder=4)


def _decorate(axes, labels: list[str], end_s: float) -> None:
    ax_speed, ax_accel, ax_jerk, ax_band, ax_ttc, ax_gap = axes
    for ax, ylabel in (
        (ax_speed, "speed\n(m/s)"),
        (ax_accel, "accel.\n(m/s²)"),
        (ax_jerk, "jerk\n(m/s³)"),
        (ax_band, "planner\nstate"),
        (ax_ttc, "TTC\n(s)"),
        (ax_gap, "gap\n(m)"),
    ):
        ax.set_ylabel(ylabel, fontsize=8)
        ax.tick_params(labelsize=7)
        if ax is not ax_band:
            ax.grid(alpha=0.3, lw=0.6)
    ax_speed.set_ylim(bottom=0)
    ax_speed.legend(
        [Line2D([], [], color="#555555", lw=1.6), Line2D([], [], color="#555555", lw=1.1, ls="--")],
        ["ego", "VRU"],
        fontsize=7,
        loc="upper right",
    )
    ax_accel.legend(
        [Line2D([], [], color="#555555", lw=1.4), Line2D([], [], color="#555555", lw=1.0, ls=":")],
        ["actual", "command"],
        fontsize=7,
        loc="lower left",
    )
    ax_band.set_yticks(range(len(labels)), list(reversed(labels)), fontsize=7)
    ax_band.set_ylim(-0.6, len(labels) - 0.4)
    ax_ttc.set_ylim(0, TTC_CAP_S)
    ax_gap.set_xlabel("time (s)", fontsize=8)
    ax_gap.set_xlim(0, max(end_s, 1e-3))


def _legend(recordings, labels, colours, modes: dict[str, str]) -> tuple[list, list[str]]:
    handles: list = [Line2D([], [], color=c, lw=2) for c in colours]
    names = list(labels)
    events = dict.fromkeys(name for r in recordings for name in r.events_s)
    for name in events:
        event_colour, line = style.EVENT_STYLES[name]
        handles.append(Line2D([], [], color=event_colour, ls=line, lw=1.2))
        names.append(KEY_EVENT_LABELS[name])
    for name, fill in modes.items():
        handles.append(Patch(facecolor=fill))
        names.append(name.replace("_", " "))
    return handles, names
