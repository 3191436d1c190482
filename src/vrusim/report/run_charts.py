"""Interactive charts of one recorded run: speeds over planner states, acceleration, clearance and TTC."""

from __future__ import annotations

import numpy as np

from vrusim.report.charts import Event, Series, Span, line_chart
from vrusim.report.html import Html, join
from vrusim.viz.recording import KEY_EVENT_LABELS, Recording

MODE_COLOURS = {"pre_slow": "#f7d117", "emergency_brake": "#e57373", "follow": "#90caf9"}
"""Background colour of each planner state in the charts (cruise: none)."""
VRU_COLOURS = ("#2e7d32", "#8e24aa", "#ef6c00", "#00838f")
TTC_CAP_S = 10.0
"""TTC above this (or infinite) is drawn as a gap, s."""


def mode_spans(recording: Recording) -> list[Span]:
    """One span per stretch of a planner state other than cruise."""
    t, modes = recording.t_s, recording.trace["planner_mode"]
    spans = []
    edges = np.flatnonzero(np.diff(modes)) + 1
    starts, ends = np.r_[0, edges], np.r_[edges, len(t) - 1]
    for start, end in zip(starts, ends, strict=True):
        name = recording.mode_names[int(modes[start])]
        if name in MODE_COLOURS:
            spans.append(Span(float(t[start]), float(t[end]), name.replace("_", " "), MODE_COLOURS[name]))
    return spans


def key_events(recording: Recording) -> list[Event]:
    """Vertical lines at the run's key events."""
    colours = {"impact": "#c62828", "brake_onset": "#6d4c41"}
    return [Event(t, KEY_EVENT_LABELS[name], colours.get(name, "#1f6fb2")) for name, t in recording.events_s.items()]


def run_charts(recording: Recording, prefix: str) -> Html:
    """Three linked charts of a run (ids `prefix`-speed, -accel, -gap), sharing one crosshair."""
    t = recording.t_s.tolist()
    trace, events = recording.trace, key_events(recording)
    vrus = [
        Series(f"VRU {i + 1} speed", t, trace["vru_speed_mps"][:, i].tolist(), VRU_COLOURS[i % 4], "m/s", dashed=True)
        for i in range(trace["vru_speed_mps"].shape[1])
    ]
    ttc = np.where(trace["ttc_s"] <= TTC_CAP_S, trace["ttc_s"], np.nan)
    return join(
        [
            line_chart(
                f"{prefix}-speed",
                "Speed and planner state",
                "t (s)",
                "speed (m/s)",
                [Series("ego speed", t, trace["ego_speed_mps"].tolist(), "#1d2430", "m/s"), *vrus],
                events,
                mode_spans(recording),
                group=prefix,
            ),
            line_chart(
                f"{prefix}-accel",
                "Ego acceleration",
                "t (s)",
                "acceleration (m/s²)",
                [
                    Series("ego acceleration", t, trace["ego_accel_mps2"].tolist(), "#1f6fb2", "m/s²"),
                    Series("planner command", t, trace["ego_command_mps2"].tolist(), "#ef6c00", "m/s²", dashed=True),
                ],
                events,
                group=prefix,
                height_px=220,
            ),
            line_chart(
                f"{prefix}-gap",
                "Clearance and time to collision",
                "t (s)",
                "clearance (m) · TTC (s)",
                [
                    Series("clearance", t, trace["clearance_m"].tolist(), "#2e7d32", "m"),
                    Series(f"TTC (≤ {TTC_CAP_S:g} s)", t, ttc.tolist(), "#c62828", "s"),
                ],
                events,
                group=prefix,
                height_px=220,
            ),
        ]
    )
