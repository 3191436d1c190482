"""Sensitivity figures of a sweep summary (matplotlib, Agg canvas, no pyplot state).

One parameter: collision probability against the parameter (bin centres, or values when grouped exactly) with
the Wilson 95 % band — or, for a metric, its mean with the p5–p95 band. Two parameters: a heat map
(pcolormesh over the bin edges) of collision probability or of the metric's mean; cells without runs stay blank.
The figure takes the summary of `summarize(results, by=[x] or [x, y], metrics=[metric])`.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from vrusim.errors import UserInputError
from vrusim.viz import figure_io
from vrusim.viz.figure_io import check_figure_path
from vrusim.viz.literal_text import literal_texts

"""Figure file suffix (case-insensitive) → matplotlib format."""
SCORES = ("safety", "efficiency", "comfort")
"""Metrics without a unit: scores in [0, 1]."""
_UNIT_SUFFIXES = (
    ("_mps3", "m/s³"),
    ("_mps2", "m/s²"),
    ("_mps", "m/s"),
    ("_kph", "km/h"),
    ("_deg", "°"),
    ("_rad", "rad"),
    ("_hz", "Hz"),
    ("_kg", "kg"),
    ("_s2", "s²"),
    ("_s", "s"),
    ("_m", "m"),
)
PROBABILITY_LABEL = "P(collision) (fraction of runs, 0–1)"
BAND_ALPHA = 0.25
MAX_VALUE_TICKS = 12
"""Parameters grouped by value get a tick per value up to this many."""


def unit_of(name: str) -> str | None:
    """The unit a column name states by its suffix (`latency_s` → "s"), "score, 0–1" for scores, else None."""
    leaf = name.rsplit(".", 1)[-1]
    if leaf in SCORES:
        return "score, 0–1"
    for suffix, unit in _UNIT_SUFFIXES:
        if leaf.endswith(suffix):
            return unit
    return None


def axis_label(name: str, prefix: str = "") -> str:
    """`prefix name (unit)`, without the brackets when the name states no unit."""
    unit = unit_of(name)
    text = f"{prefix}{name}"
    return f"{text} ({unit})" if unit else text


def check_plot_path(path: str | Path) -> Path:
    """The --plot path if a .png, .svg or .pdf can be written there; else a UserInputError naming --plot."""
    try:
        return check_figure_path(path)
    except UserInputError as error:
        raise UserInputError(f"--plot: {error}") from None


# ----------------------------------------------------------------------------------------------- axes


@dataclass(frozen=True)
class GroupAxis:
    """Where the groups of one grouping column sit on a plot axis."""

    name: str
    edges: list[float]
    """Cell boundaries, len(centres) + 1."""
    centres: list[float]
    labels: list[str] | None
    """Tick labels for categories (strings, booleans); None for numbers."""
    keys: list[Any]
    """The group key of each cell (bin index or value), in axis order."""
    binned: bool = False

    def index(self, key: Any) -> int | None:
        """Cell of a group's key (a bin dict or a value); None for a missing value."""
        if key is None:
            return None
        return self.keys.index(key["bin"] if isinstance(key, dict) else key)


def group_axis(summary: dict[str, Any], name: str) -> GroupAxis:
    """The axis of grouping column `name` of `summary`: bins, sorted numeric values or categories."""
    described = next((d for d in summary["by"] if d["name"] == name), None)
    if described is None:
        raise ValueError(f"the summary is not grouped by {name!r}")
    if described["binned"]:
        edges = list(described["edges"])
        centres = [(low + high) / 2 for low, high in itertools.pairwise(edges)]
        return GroupAxis(name, edges, centres, None, list(range(len(centres))), binned=True)
    values = sorted({group["key"][name] for group in summary["groups"] if group["key"][name] is not None}, key=_order)
    numeric = all(isinstance(v, int | float) and not isinstance(v, bool) for v in values)
    if not numeric or not values:
        positions = [float(i) for i in range(len(values))]
        edges = [i - 0.5 for i in range(len(values) + 1)]
        return GroupAxis(name, edges, positions, [str(v) for v in values], values)
    centres = [float(v) for v in values]
    if len(centres) == 1:
        half = max(abs(centres[0]) * 0.05, 0.5)
        return GroupAxis(name, [centres[0] - half, centres[0] + half], centres, None, values)
    mids = [(a + b) / 2 for a, b in itertools.pairwise(centres)]
    edges = [2 * centres[0] - mids[0], *mids, 2 * centres[-1] - mids[-1]]
    return GroupAxis(name, edges, centres, None, values)


def _order(value: Any) -> tuple[int, Any]:
    return (0, value) if isinstance(value, int | float) and not isinstance(value, bool) else (1, str(value))


def _value(group: dict[str, Any], metric: str | None) -> float | None:
    """What a group contributes: P(collision), or the metric's mean (None without values)."""
    return group["collision_probability"] if metric is None else group["metrics"][metric]["mean"]


def _band(group: dict[str, Any], metric: str | None) -> tuple[float, float]:
    if metric is None:
        low, high = group["collision_probability_95"]
        return low, high
    stats = group["metrics"][metric]
    return stats["p5"], stats["p95"]


def _title(summary: dict[str, Any], what: str) -> str:
    name = summary.get("name") or Path(summary["results"]).name
    status = summary["status"]
    runs = summary["overall"]["runs"]
    return f"{name}: {what}\n{runs} runs, {status}"


def _decorate_axis(ax, axis: GroupAxis, which: str) -> None:
    """Axis label with the unit; category names as ticks."""
    label = axis_label(axis.name) + (", bins" if axis.binned else "")
    set_ticks = ax.set_xticks if which == "x" else ax.set_yticks
    if axis.labels is not None:
        set_ticks(axis.centres, axis.labels)
    elif not axis.binned and len(axis.centres) <= MAX_VALUE_TICKS:
        set_ticks(axis.centres, [f"{value:g}" for value in axis.centres])
    (ax.set_xlabel if which == "x" else ax.set_ylabel)(label)


# ----------------------------------------------------------------------------------------------- figures


def sensitivity_figure(
    summary: dict[str, Any], x: str, y: str | None = None, metric: str | None = None, dpi: float = 100.0
) -> Figure:
    """A line plot with band (one parameter) or a heat map (two) of P(collision) or of `metric`'s mean."""
    if metric is not None and metric not in summary["metrics"]:
        raise UserInputError(f"--metric: {metric!r} is not among the summarised metrics")
    fig = Figure(figsize=(7.0, 4.8), dpi=dpi, layout="constrained")
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    if y is None:
        _line(ax, summary, group_axis(summary, x), metric)
    else:
        _heat_map(fig, ax, summary, group_axis(summary, x), group_axis(summary, y), metric)
    return literal_texts(fig)


def _line(ax, summary: dict[str, Any], axis: GroupAxis, metric: str | None) -> None:
    points = []
    for group in summary["groups"]:
        cell, value = axis.index(group["key"][axis.name]), _value(group, metric)
        if cell is not None and value is not None:
            points.append((axis.centres[cell], value, *_band(group, metric)))
    xs, ys, lows, highs = np.array(sorted(points), dtype=float).reshape(-1, 4).T
    band_label = "Wilson 95 % interval" if metric is None else "p5–p95"
    line_label = "P(collision)" if metric is None else f"mean {metric}"
    if axis.labels is None and len(xs) > 1:
        ax.fill_between(xs, lows, highs, alpha=BAND_ALPHA, linewidth=0, label=band_label)
        ax.plot(xs, ys, "o-", label=line_label)
    else:
        ax.errorbar(xs, ys, yerr=[ys - lows, highs - ys], fmt="o", capsize=4, label=f"{line_label}, {band_label}")
    _decorate_axis(ax, axis, "x")
    if metric is None:
        ax.set_ylim(-0.02, 1.02)
        ax.set_ylabel(PROBABILITY_LABEL)
        what = f"collision probability vs {axis.name} (Wilson 95 %)"
    else:
        ax.set_ylabel(axis_label(metric, "mean "))
        what = f"mean {metric} vs {axis.name} (band p5–p95)"
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize=8)
    ax.set_title(_title(summary, what), fontsize=10, loc="left")


def heat_map_values(summary: dict[str, Any], x: GroupAxis, y: GroupAxis, metric: str | None = None) -> np.ndarray:
    """Cell values [len(y cells), len(x cells)]: P(collision) or the metric's mean; NaN where no run fell."""
    values = np.full((len(y.centres), len(x.centres)), np.nan)
    for group in summary["groups"]:
        column, row = x.index(group["key"][x.name]), y.index(group["key"][y.name])
        value = _value(group, metric)
        if column is not None and row is not None and value is not None:
            values[row, column] = value
    return values


def _heat_map(fig: Figure, ax, summary: dict[str, Any], x: GroupAxis, y: GroupAxis, metric: str | None) -> None:
    values = np.ma.masked_invalid(heat_map_values(summary, x, y, metric))
    limits: dict[str, float] = {"vmin": 0.0, "vmax": 1.0} if metric is None else {}
    mesh = ax.pcolormesh(x.edges, y.edges, values, cmap="viridis", shading="flat", **limits)
    label = PROBABILITY_LABEL if metric is None else axis_label(metric, "mean ")
    fig.colorbar(mesh, ax=ax, label=label)
    _decorate_axis(ax, x, "x")
    _decorate_axis(ax, y, "y")
    what = "collision probability" if metric is None else f"mean {metric}"
    ax.set_title(_title(summary, f"{what} by {x.name} × {y.name} (blank: no runs)"), fontsize=10, loc="left")


def write_figure(fig: Figure, path: str | Path) -> Path:
    """Save `fig` atomically as PNG, SVG or PDF (by suffix) at the figure's dpi; return the path."""
    return figure_io.write_figure(fig, check_plot_path(path), fig.dpi)


def write_sensitivity_plot(
    summary: dict[str, Any], path: str | Path, x: str, y: str | None = None, metric: str | None = None
) -> Figure:
    """Build the figure (see `sensitivity_figure`), write it to `path` and return it."""
    check_plot_path(path)
    fig = sensitivity_figure(summary, x, y, metric)
    write_figure(fig, path)
    return fig
