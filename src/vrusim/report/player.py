"""The scene player: a top-down view of one or more recorded runs that plays in the browser (report/assets/player.js).

`player_data(recordings)` turns Recordings into a JSON document: the static scene (road surfaces and lines,
obstacles, planned paths, RSU ranges; metres, world frame) and, per run, frames sampled from the trace (ego
centre and heading, speed, planner state, VRU positions and what perceived them), key events and the impact
point. Frames are every `stride`-th trace sample (the last one always kept) with the stride chosen so the frames
of all runs together stay within `FRAME_BUDGET_BYTES` and no closer than `MIN_FRAME_STEP_S`; the browser
interpolates positions between frames. `player(recordings, ...)` wraps the document in the player's HTML (its
controls are built by the script); the page inlines player.js and player.css (`report.page.render`).

The drawn scale is exposed for tests and scripts: each panel's `<svg>` carries `data-scale-px-per-m`,
`data-tx-px` and `data-ty-px` (pixel = (tx + s·x, ty − s·y) in the svg's viewBox units), and
`window.vrusimPlayer.players[id]` offers `time()`, `seek(t_s)`, `play()`, `pause()` and `view(panel)`.
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any
from uuid import uuid4

import numpy as np

from vrusim.report.html import Html, script_json, tag
from vrusim.report.page import asset
from vrusim.scenario.schema import Road, Scenario
from vrusim.sim.observation import SOURCE_SENSOR, SOURCE_V2X
from vrusim.viz import style
from vrusim.viz.recording import KEY_EVENT_LABELS, Recording

FRAME_BUDGET_BYTES = 600_000
"""The frames of all runs of one player together take at most about this many bytes of JSON."""
MIN_FRAME_STEP_S = 0.02
"""Frames are at least this far apart (50 per simulated second), s."""
POSITION_DIGITS = 3
"""Decimals kept of positions in metres (1 mm)."""
SPEEDS = (0.25, 0.5, 1.0, 2.0, 4.0)
"""Playback speeds offered (× real time)."""
LAYERS = (
    ("road", "road"),
    ("obstacles", "obstacles"),
    ("paths", "planned paths"),
    ("trails", "travelled"),
    ("sensor", "sensor sector"),
    ("shadows", "occlusion shadows"),
    ("v2x", "RSU and V2X"),
    ("vrus", "VRUs"),
    ("ego", "ego"),
    ("impact", "impact"),
)
"""(layer key, label) of every toggleable layer, bottom to top."""


@dataclass(frozen=True)
class Sampling:
    """How a run's trace was sampled: every `stride`-th sample, `frames` of them, `bytes` of JSON."""

    stride: int
    frames: int
    bytes: int


def _rounded(values: np.ndarray, digits: int) -> list[float | None]:
    return [None if not math.isfinite(v) else round(float(v), digits) for v in np.asarray(values, dtype=float)]


def _css(colour: Any) -> str:
    """A matplotlib colour (hex, or an RGB(A) tuple of 0–1 floats) as CSS."""
    if isinstance(colour, str):
        return colour
    r, g, b, *a = colour
    return f"rgba({round(r * 255)},{round(g * 255)},{round(b * 255)},{a[0] if a else 1:g})"


def road_shapes(road: Road) -> dict[str, list]:
    """The road as `surfaces` (closed outlines) and `lines` ({kind, style, points}), m: the road's own geometry
    when it has some (imported), else the generated layout (as `viz.scene` draws it)."""
    if road.lines is not None or road.surfaces is not None:
        return {
            "surfaces": [s.points for s in road.surfaces or ()],
            "lines": [{"kind": ln.kind, "style": ln.style, "points": ln.points} for ln in road.lines or ()],
            "marking": style.MARKING if road.surfaces else style.ROAD,
        }
    w, half = road.lane_width_m, road.length_m / 2
    surfaces = [[[-half, -w], [half, -w], [half, w], [-half, w]]]
    lines: list[dict] = []

    def line(kind: str, line_style: str, *points: tuple[float, float]) -> None:
        lines.append({"kind": kind, "style": line_style, "points": [list(p) for p in points]})

    if road.layout == "straight":
        for y in (-w, w):
            line("edge", "solid", (-half, y), (half, y))
        line("centre", "broken", (-half, 0.0), (half, 0.0))
    else:
        surfaces.append([[-w, -half], [w, -half], [w, half], [-w, half]])
        for sign in (-1, 1):
            for edge in (-w, w):
                line("edge", "solid", (sign * w, edge), (sign * half, edge))
                line("edge", "solid", (edge, sign * w), (edge, sign * half))
            line("centre", "broken", (sign * w, 0.0), (sign * half, 0.0))
            line("centre", "broken", (0.0, sign * w), (0.0, sign * half))
        for x0, y0, x1, y1 in ((-w, -w, -w, 0), (w, 0, w, w), (0, w, -w, w), (w, -w, 0, -w)):
            line("stop", "solid", (x0, y0), (x1, y1))
    return {"surfaces": surfaces, "lines": lines, "marking": style.MARKING}


def _obstacles(scenario: Scenario) -> list[list[float]]:
    """Each obstacle as [centre x, centre y, heading x, heading y, half length, half width], m."""
    rows = []
    for box in scenario.obstacles:
        heading = math.radians(box.centre.heading_deg)
        rows.append(
            [
                box.centre.x_m,
                box.centre.y_m,
                round(math.cos(heading), 9),
                round(math.sin(heading), 9),
                box.length_m / 2,
                box.width_m / 2,
            ]
        )
    return rows


def _polyline(points: np.ndarray, digits: int = 2, max_points: int = 400) -> list[list[float]]:
    """A path's points rounded to `digits`, thinned to about `max_points` (the last kept)."""
    if len(points) > max_points:
        keep = np.unique(np.r_[np.arange(0, len(points), math.ceil(len(points) / max_points)), len(points) - 1])
        points = points[keep]
    return [[round(float(x), digits), round(float(y), digits)] for x, y in points]


def impact_point(recording: Recording) -> dict[str, float] | None:
    """Where the impact happened: time and the point on the struck VRU's footprint facing the ego, m."""
    impact_s = recording.events_s.get("impact")
    if impact_s is None or not recording.scenario.vrus:
        return None
    trace, index = recording.trace, recording.nearest_index(impact_s)
    cx, cy = float(trace["ego_x_m"][index]), float(trace["ego_y_m"][index])
    xs, ys = trace["vru_x_m"][index], trace["vru_y_m"][index]
    k = int(np.argmin(np.hypot(xs - cx, ys - cy)))
    vx, vy = float(xs[k]), float(ys[k])
    gap = max(math.hypot(cx - vx, cy - vy), 1e-9)
    reach = min(recording.scenario.vrus[k].footprint_m, gap)
    x, y = vx + (cx - vx) * reach / gap, vy + (cy - vy) * reach / gap
    return {"t_s": float(impact_s), "x_m": round(x, 3), "y_m": round(y, 3), "vru": k}


def frames(recording: Recording, stride: int) -> dict[str, list]:
    """Every `stride`-th trace sample (and the last) as columns: t_s, ego x/y (m), heading (deg, unwrapped so it
    interpolates), speed (m/s), planner state (index into the run's `modes`), and per VRU x/y (m), perception
    source (bit 1 sensor, bit 2 V2X) and the age of the V2X message the ego held about it (s, null: none), as
    decided at that time."""
    trace, n = recording.trace, len(recording.t_s)
    keep = np.unique(np.r_[np.arange(0, n, stride), n - 1])
    decided = np.minimum(keep + 1, n - 1)  # decision columns: row i + 1 holds what was decided at t_s[i]
    heading = np.degrees(np.unwrap(np.arctan2(trace["ego_heading_y"], trace["ego_heading_x"])))
    d = POSITION_DIGITS
    ages = trace.get("vru_v2x_age_s")
    if ages is None:  # a trace without the column (an older trace file): no message ages
        ages = np.full(trace["vru_x_m"].shape, np.nan)
    return {
        "t_s": _rounded(recording.t_s[keep], 6),
        "x_m": _rounded(trace["ego_x_m"][keep], d),
        "y_m": _rounded(trace["ego_y_m"][keep], d),
        "heading_deg": _rounded(heading[keep], 3),
        "speed_mps": _rounded(trace["ego_speed_mps"][keep], 2),
        "mode": [int(m) for m in trace["planner_mode"][decided]],
        "vru_x_m": [_rounded(trace["vru_x_m"][keep, k], d) for k in range(trace["vru_x_m"].shape[1])],
        "vru_y_m": [_rounded(trace["vru_y_m"][keep, k], d) for k in range(trace["vru_y_m"].shape[1])],
        "vru_source": [[int(s) for s in trace["vru_source"][decided, k]] for k in range(trace["vru_source"].shape[1])],
        "vru_v2x_age_s": [_rounded(ages[decided, k], 2) for k in range(ages.shape[1])],
    }


def _size(document: Any) -> int:
    return len(json.dumps(document, separators=(",", ":")))


def choose_stride(recordings: Sequence[Recording], budget_bytes: int = FRAME_BUDGET_BYTES) -> Sampling:
    """The smallest stride, at least `MIN_FRAME_STEP_S` / dt, whose frames of all `recordings` fit the budget."""
    dt = min(r.scenario.sim.dt_s for r in recordings)
    stride = max(1, round(MIN_FRAME_STEP_S / dt))
    while True:
        sampled = [frames(r, stride) for r in recordings]
        size = sum(_size(f) for f in sampled)
        count = max(len(f["t_s"]) for f in sampled)
        if size <= budget_bytes or count <= 2:
            return Sampling(stride, count, size)
        stride = max(stride + 1, math.ceil(stride * size / budget_bytes))


def _run(recording: Recording, label: str, colour: str, stride: int) -> dict[str, Any]:
    """One run's part of the player document."""
    scenario = recording.scenario
    v2x, sensor = scenario.v2x, scenario.sensor
    rsu = None
    if v2x.enabled and v2x.rsu is not None:
        rsu = {"x_m": v2x.rsu.x_m, "y_m": v2x.rsu.y_m, "comm_m": v2x.comm_range_m, "coverage_m": v2x.coverage_range_m}
    first_v2x = recording.summary.get("first_v2x_message_s")
    return {
        "label": label,
        "colour": colour,
        "scenario": scenario.name,
        "planner": recording.summary.get("planner"),
        "v2x": bool(v2x.enabled),
        "ego": {"length_m": scenario.ego.length_m, "width_m": scenario.ego.width_m},
        "sensor": {"enabled": sensor.enabled, "fov_deg": sensor.fov_deg, "range_m": sensor.effective_range_m},
        "rsu": rsu,
        "first_v2x_message_s": first_v2x,
        "route": _polyline(recording.ego_route_xy_m()),
        "vrus": [
            {
                "type": str(vru.type),
                "colour": style.vru_colour(vru.type),
                "footprint_m": vru.footprint_m,
                "path": _polyline(path),
            }
            for vru, path in zip(scenario.vrus, recording.vru_paths_xy_m(), strict=True)
        ],
        "obstacles": _obstacles(scenario),
        "road": road_shapes(scenario.road),
        "modes": list(recording.mode_names),
        "mode_colours": {name: style.mode_colour(name, i) for i, name in enumerate(recording.mode_names)},
        "events": [
            {"name": name, "label": KEY_EVENT_LABELS[name], "t_s": t} for name, t in sorted(recording.events_s.items())
        ],
        "impact": impact_point(recording),
        "frames": frames(recording, stride),
    }


def _with_sensor_reach(box: tuple[float, float, float, float], recordings: Sequence[Recording]) -> list[float]:
    """The figures' view box grown to half the sensor range ahead of the ego at its first and last sample, m."""
    x0, x1, y0, y1 = box
    for rec in recordings:
        trace, reach = rec.trace, rec.scenario.ego.length_m / 2 + rec.scenario.sensor.effective_range_m / 2
        for i in (0, -1):
            x = float(trace["ego_x_m"][i] + reach * trace["ego_heading_x"][i])
            y = float(trace["ego_y_m"][i] + reach * trace["ego_heading_y"][i])
            x0, x1, y0, y1 = min(x0, x), max(x1, x), min(y0, y), max(y1, y)
    return [x0, x1, y0, y1]


def run_colours(count: int) -> list[str]:
    """The ego colour of each of `count` runs of one player (the first in the figures' ego blue)."""
    spare = style.RECORDING_COLOURS
    return [style.EGO_FACE if i == 0 else spare[i % len(spare)] for i in range(count)]


def player_data(
    recordings: Sequence[Recording],
    labels: Sequence[str] | None = None,
    budget_bytes: int = FRAME_BUDGET_BYTES,
) -> dict[str, Any]:
    """The player's JSON document of `recordings` (one timeline; compared when more than one)."""
    from vrusim.viz.scene import view_window

    recordings = list(recordings)
    if not recordings:
        raise ValueError("player_data needs at least one recording")
    labels = list(labels) if labels is not None else style.recording_labels(recordings)
    sampling = choose_stride(recordings, budget_bytes)
    window = view_window(recordings)
    box = _with_sensor_reach(window.box, recordings)
    colours = run_colours(len(recordings))
    return {
        "version": 1,
        "t_end_s": max(float(r.t_s[-1]) for r in recordings),
        "dt_s": min(r.scenario.sim.dt_s for r in recordings),
        "stride": sampling.stride,
        "frame_bytes": sampling.bytes,
        "budget_bytes": budget_bytes,
        "box_m": [round(v, 3) for v in box],
        "follow_size_m": [round(window.width_m, 3), round(window.height_m, 3)],
        "follow": window.follow,
        "speeds": list(SPEEDS),
        "layers": [{"key": key, "label": label} for key, label in LAYERS],
        "colours": {
            "ground": style.GROUND,
            "road": style.ROAD,
            "ego_face": style.EGO_FACE,
            "ego_edge": style.EGO_EDGE,
            "sensor_face": _css(style.SENSOR_FACE),
            "sensor_edge": _css(style.SENSOR_EDGE),
            "shadow": "rgba(40,40,40,0.28)",
            "v2x": style.V2X,
            "obstacle_face": style.OBSTACLE_FACE,
            "obstacle_edge": style.OBSTACLE_EDGE,
            "planned": style.PLANNED,
            "impact": style.IMPACT,
            "detected_sensor": style.DETECTED_SENSOR,
        },
        "source_bits": {"sensor": SOURCE_SENSOR, "v2x": SOURCE_V2X},
        "runs": [
            _run(r, label, colour, sampling.stride)
            for r, label, colour in zip(recordings, labels, colours, strict=True)
        ],
    }


def player(
    recordings: Sequence[Recording],
    element_id: str = "player",
    chart_group: str | Sequence[str] | None = None,
    labels: Sequence[str] | None = None,
    budget_bytes: int = FRAME_BUDGET_BYTES,
) -> Html:
    """The player's HTML: a box the script fills with controls and panels, its data inline; `chart_group` (one
    name or several) links its time cursor with the report's charts of those groups (report.js) both ways."""
    groups = [chart_group] if isinstance(chart_group, str) else list(chart_group or ())
    data = player_data(recordings, labels, budget_bytes)
    runs = len(data["runs"])
    note = (
        f"{runs} runs on one timeline. " if runs > 1 else ""
    ) + "Play, scrub or step through the run; drag to pan, the wheel or +/− to zoom; click a chart to jump there."
    return tag(
        "div",
        tag("p", note, class_="note"),
        tag("noscript", "The scene player needs JavaScript; the figures below show the same run."),
        script_json(data, class_="player-data"),
        class_="player",
        id=element_id,
        data_group=" ".join(groups) or None,
        data_runs=runs,
    )


EMBED_STYLE = "--ink:#1d2430;--muted:#5b6472;--line:#d9dde3;--accent:#1f6fb2;font-family:system-ui,sans-serif"
"""The report's colour variables, set on an embedded player's box (a notebook has no report style sheet)."""


def embedded_player(recordings: Sequence[Recording], labels: Sequence[str] | None = None) -> str:
    """The player as one HTML fragment with its style and script inline, under a fresh id (a Jupyter output;
    several on one page each start once)."""
    box = player(recordings, f"vrusim-player-{uuid4().hex[:12]}", labels=labels)
    return (
        f'<div class="vrusim-embed" style="{EMBED_STYLE}"><style>{asset("player.css")}</style>{box}'
        f"<script>{asset('player.js')}</script></div>"
    )
