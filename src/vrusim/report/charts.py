"""Interactive line charts as inline SVG: drawn here (visible without script), made interactive by report.js.

Each chart is a `<div class="chart">` holding a legend (buttons that hide or show a series), the SVG (axes,
shaded spans such as planner states, event lines, bands, lines), a read-out line, and its data as JSON. Moving
the pointer over the plot shows every series' value at that x; charts with the same `group` share the
crosshair (the time axes of one run). A few kB of script instead of a plotting library keeps reports small.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from vrusim.report.html import Html, esc, script_json, tag

WIDTH_PX, HEIGHT_PX = 860, 280
MARGIN_PX = {"left": 62, "right": 16, "top": 14, "bottom": 42}
MAX_POINTS = 400
"""Longer series are thinned to about this many points (every k-th sample, the last one kept)."""
FONT = "font-family:system-ui,sans-serif;font-size:11px"


@dataclass(frozen=True)
class Series:
    """One line: x and y values (None / NaN / ±inf: a gap), its unit and display digits for the read-out."""

    name: str
    x: Sequence[float]
    y: Sequence[float | None]
    colour: str
    unit: str = ""
    digits: int = 2
    dashed: bool = False
    band: tuple[Sequence[float], Sequence[float]] | None = None
    """Shaded (low, high) around the line, e.g. a 95 % interval."""
    points: bool = False
    """Draw a marker at every point (sparse data such as sweep groups)."""
    labels: Sequence[str] | None = None
    """Per-point text added to the read-out (e.g. "12 of 40 runs")."""


@dataclass(frozen=True)
class Event:
    """A vertical line at `x` with a label (first perception, brake onset, impact, ...)."""

    x: float
    label: str
    colour: str = "#555555"


@dataclass(frozen=True)
class Span:
    """A shaded x interval behind the lines (a planner state), with its label."""

    x0: float
    x1: float
    label: str
    colour: str


def _finite(values: Sequence[float | None]) -> np.ndarray:
    array = np.array([np.nan if v is None else v for v in values], dtype=float)
    array[~np.isfinite(array)] = np.nan
    return array


def _thin(series: Series) -> Series:
    """At most about MAX_POINTS points: every k-th sample plus the last."""
    n = len(series.x)
    if n <= MAX_POINTS:
        return series
    keep = np.unique(np.r_[np.arange(0, n, math.ceil(n / MAX_POINTS)), n - 1])
    pick = lambda values: [values[i] for i in keep]  # noqa: E731
    band = None if series.band is None else (pick(series.band[0]), pick(series.band[1]))
    labels = None if series.labels is None else pick(series.labels)
    return Series(
        series.name,
        pick(series.x),
        pick(series.y),
        series.colour,
        series.unit,
        series.digits,
        series.dashed,
        band,
        series.points,
        labels,
    )


def nice_ticks(low: float, high: float, count: int = 6) -> list[float]:
    """Round tick values covering [low, high], about `count` of them (steps 1, 2, 2.5, 5 × 10^k)."""
    if not (math.isfinite(low) and math.isfinite(high)) or high <= low:
        return [low]
    raw = (high - low) / max(count - 1, 1)
    power = 10 ** math.floor(math.log10(raw))
    step = next(m * power for m in (1, 2, 2.5, 5, 10) if m * power >= raw)
    first = math.ceil(low / step - 1e-9) * step
    ticks, value = [], first
    while value <= high + 1e-9 * step:
        ticks.append(round(value, 12) + 0.0)
        value += step
    return ticks


def _domain(values: list[np.ndarray], fixed: tuple[float, float] | None, pad: float) -> tuple[float, float]:
    if fixed is not None:
        return fixed
    data = np.concatenate([v[np.isfinite(v)] for v in values] or [np.array([0.0])])
    low, high = (float(data.min()), float(data.max())) if data.size else (0.0, 1.0)
    if high - low < 1e-12:
        low, high = low - 1.0, high + 1.0
    margin = pad * (high - low)
    return low - margin, high + margin


def _path(xs: np.ndarray, ys: np.ndarray) -> str:
    """SVG path data with a new subpath after every gap (NaN)."""
    parts, pen_down = [], False
    for x, y in zip(xs, ys, strict=True):
        if not (math.isfinite(x) and math.isfinite(y)):
            pen_down = False
            continue
        parts.append(f"{'L' if pen_down else 'M'}{x:.1f},{y:.1f}")
        pen_down = True
    return "".join(parts)


def _event_label(event: Event, x_px: float, y_px: float, right_px: float) -> str:
    """An event's label beside its line: to the right, or to the left near the right edge (never clipped)."""
    near_edge = x_px > right_px - 8 * len(event.label)
    return tag(
        "text",
        event.label,
        x=f"{x_px - 3 if near_edge else x_px + 3:.1f}",
        y=y_px,
        text_anchor="end" if near_edge else "start",
        style=FONT,
        fill=event.colour,
    )


def _label(value: float) -> str:
    return f"{value:g}" if abs(value) < 1e5 else f"{value:.3g}"


def line_chart(
    chart_id: str,
    title: str,
    x_label: str,
    y_label: str,
    series: Sequence[Series],
    events: Sequence[Event] = (),
    spans: Sequence[Span] = (),
    group: str | None = None,
    x_digits: int = 2,
    y_range: tuple[float, float] | None = None,
    height_px: int = HEIGHT_PX,
) -> Html:
    """An interactive line chart (see module docstring); `group` links crosshairs of charts sharing an x axis."""
    series = [_thin(s) for s in series]
    left, right = MARGIN_PX["left"], WIDTH_PX - MARGIN_PX["right"]
    top, bottom = MARGIN_PX["top"], height_px - MARGIN_PX["bottom"]
    xs = [_finite(s.x) for s in series]
    ys = [_finite(s.y) for s in series]
    bands = [(_finite(s.band[0]), _finite(s.band[1])) for s in series if s.band is not None]
    x0, x1 = _domain([*xs, np.array([e.x for e in events], dtype=float)], None, 0.0)
    y0, y1 = _domain([*ys, *(b for pair in bands for b in pair)], y_range, 0.06)
    px = lambda x: left + (np.asarray(x, dtype=float) - x0) / (x1 - x0) * (right - left)  # noqa: E731
    py = lambda y: bottom + (np.clip(np.asarray(y, dtype=float), y0, y1) - y0) / (y1 - y0) * (top - bottom)  # noqa: E731

    parts: list[Html] = []
    for span in spans:
        a, b = float(px(max(span.x0, x0))), float(px(min(span.x1, x1)))
        if b > a:
            parts.append(
                tag(
                    "rect",
                    tag("title", span.label),
                    x=f"{a:.1f}",
                    y=top,
                    width=f"{b - a:.1f}",
                    height=bottom - top,
                    fill=span.colour,
                    fill_opacity="0.35",
                    class_="span",
                )
            )
    grid = []
    for value in nice_ticks(y0, y1, 5):
        y = float(py(value))
        grid.append(tag("line", x1=left, x2=right, y1=f"{y:.1f}", y2=f"{y:.1f}", stroke="#e4e7ec"))
        grid.append(tag("text", _label(value), x=left - 6, y=f"{y + 4:.1f}", text_anchor="end", style=FONT))
    for value in nice_ticks(x0, x1, 9):
        x = float(px(value))
        grid.append(tag("line", x1=f"{x:.1f}", x2=f"{x:.1f}", y1=bottom, y2=bottom + 4, stroke="#666"))
        grid.append(tag("text", _label(value), x=f"{x:.1f}", y=bottom + 16, text_anchor="middle", style=FONT))
    grid.append(tag("rect", x=left, y=top, width=right - left, height=bottom - top, fill="none", stroke="#999"))
    grid.append(tag("text", x_label, x=(left + right) / 2, y=height_px - 6, text_anchor="middle", style=FONT))
    grid.append(
        tag(
            "text",
            y_label,
            x=12,
            y=(top + bottom) / 2,
            text_anchor="middle",
            style=FONT,
            transform=f"rotate(-90 12 {(top + bottom) / 2})",
        )
    )
    parts.append(tag("g", *grid, class_="axes"))
    for number, event in enumerate(sorted(events, key=lambda e: e.x)):
        x, label_y = float(px(event.x)), top + 11 + 12 * (number % 3)
        parts.append(
            tag(
                "g",
                tag("title", f"{event.label}: {event.x:.2f}"),
                tag(
                    "line", x1=f"{x:.1f}", x2=f"{x:.1f}", y1=top, y2=bottom, stroke=event.colour, stroke_dasharray="4 3"
                ),
                _event_label(event, x, label_y, right),
                class_="event",
            )
        )
    for index, (s, x, y) in enumerate(zip(series, xs, ys, strict=True)):
        layer = []
        if s.band is not None:
            low, high = _finite(s.band[0]), _finite(s.band[1])
            ok = np.isfinite(x) & np.isfinite(low) & np.isfinite(high)
            if ok.any():
                outline = [
                    *zip(px(x[ok]), py(high[ok]), strict=True),
                    *zip(px(x[ok][::-1]), py(low[ok][::-1]), strict=True),
                ]
                points = " ".join(f"{a:.1f},{b:.1f}" for a, b in outline)
                layer.append(tag("polygon", points=points, fill=s.colour, fill_opacity="0.18", stroke="none"))
        layer.append(
            tag(
                "path",
                d=_path(px(x), np.where(np.isfinite(y), py(y), np.nan)),
                fill="none",
                stroke=s.colour,
                stroke_width="1.8",
                stroke_dasharray="6 4" if s.dashed else None,
            )
        )
        if s.points:
            layer += [
                tag("circle", cx=f"{float(px(a)):.1f}", cy=f"{float(py(b)):.1f}", r="3", fill=s.colour)
                for a, b in zip(x, y, strict=True)
                if math.isfinite(a) and math.isfinite(b)
            ]
        parts.append(tag("g", *layer, class_="series", data_series=index))
    parts.append(
        tag(
            "line",
            class_="crosshair",
            x1=left,
            x2=left,
            y1=top,
            y2=bottom,
            stroke="#222",
            stroke_width="0.8",
            visibility="hidden",
        )
    )
    parts += [tag("circle", class_="dot", r="4", fill=s.colour, stroke="#fff", visibility="hidden") for s in series]
    svg = tag(
        "svg",
        *parts,
        xmlns="http://www.w3.org/2000/svg",
        viewBox=f"0 0 {WIDTH_PX} {height_px}",
        width=WIDTH_PX,
        height=height_px,
        role="img",
        aria_label=title,
    )
    legend = [
        tag(
            "button",
            tag("i", style=f"background:{esc(s.colour)}"),
            s.name,
            type="button",
            data_series=i,
            aria_pressed="true",
        )
        for i, s in enumerate(series)
    ] + [
        tag("span", tag("i", style=f"background:{esc(sp.colour)};opacity:.5;height:10px"), sp.label)
        for sp in dict((sp.label, sp) for sp in spans).values()
    ]
    data = {
        "x_map": [x0, x1, left, right],
        "y_map": [y0, y1, bottom, top],
        "x_label": x_label,
        "x_digits": x_digits,
        "snap": x1 - x0,
        "group": group,
        "hint": "Move the pointer over the plot to read values; click a legend entry to hide or show it.",
        "series": [
            {
                "name": s.name,
                "unit": s.unit,
                "digits": s.digits,
                "x": _json_list(x),
                "y": _json_list(y),
                "labels": None if s.labels is None else list(s.labels),
            }
            for s, x, y in zip(series, xs, ys, strict=True)
        ],
    }
    return tag(
        "div",
        tag("div", title, class_="title"),
        tag("div", *legend, class_="legend"),
        svg,
        tag("div", "", class_="readout", aria_live="polite"),
        script_json(data, class_="chart-data"),
        class_="chart",
        id=chart_id,
    )


def _json_list(values: np.ndarray) -> list[float | None]:
    return [None if not math.isfinite(v) else round(float(v), 4) for v in values]
