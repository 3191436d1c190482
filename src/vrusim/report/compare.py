"""Report of `vrusim compare --report`: the comparison table, one scene player with every combination on one
timeline (side by side or overlaid), and their speed and clearance overlaid in linked charts."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from vrusim.report.charts import Event, Series, line_chart
from vrusim.report.html import Column, Html, facts, join, table
from vrusim.report.page import Report, Section
from vrusim.report.player import player, run_colours
from vrusim.report.run_charts import TTC_CAP_S
from vrusim.viz.recording import KEY_EVENT_LABELS, Recording

GROUP = "compare"
"""Chart group linked with the player's time cursor."""

COLUMNS = (
    Column("runs", "Runs", 0),
    Column("collisions", "Collisions", 0),
    Column("collision_probability", "P(collision)", 3),
    Column("mean_impact_speed_mps", "Impact speed (m/s)", 2),
    Column("min_ttc_s", "Min TTC (s)", 2),
    Column("mean_first_sensor_detection_s", "First sensor detection (s)", 2),
    Column("mean_first_v2x_message_s", "First V2X message (s)", 2),
    Column("safety", "Safety", 3),
    Column("efficiency", "Efficiency", 3),
    Column("comfort", "Comfort", 3),
)


def label_of(planner: str, v2x: str) -> str:
    """A combination's label: "fsm · V2X off"."""
    return f"{planner} · V2X {v2x}"


def comparison_charts(recordings: Sequence[Recording], labels: Sequence[str], prefix: str = GROUP) -> Html:
    """Ego speed and clearance / TTC of every run overlaid (ids `prefix`-speed, `prefix`-gap), one crosshair."""
    colours = run_colours(len(recordings))
    events = [
        Event(t, f"{label}: {KEY_EVENT_LABELS[name]}", colour)
        for rec, label, colour in zip(recordings, labels, colours, strict=True)
        for name, t in rec.events_s.items()
        if name in ("brake_onset", "impact")
    ]
    speed, gap = [], []
    for rec, label, colour in zip(recordings, labels, colours, strict=True):
        t = rec.t_s.tolist()
        speed.append(Series(f"{label} ego speed", t, rec.trace["ego_speed_mps"].tolist(), colour, "m/s"))
        gap.append(Series(f"{label} clearance", t, rec.trace["clearance_m"].tolist(), colour, "m"))
        ttc = np.where(rec.trace["ttc_s"] <= TTC_CAP_S, rec.trace["ttc_s"], np.nan)
        gap.append(Series(f"{label} TTC", t, ttc.tolist(), colour, "s", dashed=True))
    return join(
        [
            line_chart(f"{prefix}-speed", "Ego speed", "t (s)", "speed (m/s)", speed, events, group=prefix),
            line_chart(
                f"{prefix}-gap",
                "Clearance and time to collision (dashed)",
                "t (s)",
                "clearance (m) · TTC (s)",
                gap,
                events,
                group=prefix,
                height_px=240,
            ),
        ]
    )


def compare_report(
    rows: list[dict], recordings: Sequence[Recording], labels: Sequence[str], scenario_name: str, seeds: int
) -> Report:
    """The comparison's rows (one per planner × V2X setting) and one recorded run of each (its first seed)."""
    table_rows = [(label, {**row, "combination": label}) for row, label in zip(rows, labels, strict=True)]
    what = [
        ("scenario", scenario_name),
        ("combinations", ", ".join(labels)),
        ("seeds per combination", str(seeds)),
        ("shown in the player", "the first seed of each combination"),
    ]
    sections = [
        Section("what-was-compared", "What was compared", facts(what, "compare-facts")),
        Section(
            "comparison",
            "Outcomes",
            table("comparison", COLUMNS, table_rows, row_header=Column("combination", "Planner · V2X")),
        ),
        Section("scene-player", "Scene player", player(recordings, "player", chart_group=GROUP, labels=labels)),
        Section("charts", "Interactive time series", comparison_charts(recordings, labels)),
    ]
    return Report(
        kind="compare",
        title=f"vrusim compare: {scenario_name}",
        lead=f"{scenario_name}: {len(labels)} combinations of planner and V2X setting on one timeline.",
        sections=sections,
        results={"scenario": scenario_name, "rows": rows, "labels": list(labels)},
    )
