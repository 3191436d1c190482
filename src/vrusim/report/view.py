"""The page of `vrusim view`: the scene player of one run or of several compared (V2X off / on), with its linked
charts; and a Recording read back from a saved trace file (`vrusim run --trace`) plus the scenario it ran."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from vrusim.engine.trace_file import read_trace
from vrusim.errors import UserInputError
from vrusim.metrics.outcome import outcome_of
from vrusim.report.compare import comparison_charts
from vrusim.report.html import facts
from vrusim.report.page import Report, Section
from vrusim.report.player import player
from vrusim.report.run_charts import run_charts
from vrusim.scenario.schema import Scenario
from vrusim.sim.observation import SOURCE_SENSOR, SOURCE_V2X
from vrusim.viz.recording import Recording, key_events
from vrusim.viz.style import recording_labels


def view_report(recordings: Sequence[Recording], labels: Sequence[str] | None = None, note: str = "") -> Report:
    """A page with the player of `recordings` (one timeline) and their charts, linked."""
    recordings = list(recordings)
    labels = list(labels) if labels is not None else recording_labels(recordings)
    name = recordings[0].scenario.name
    single = len(recordings) == 1
    charts = run_charts(recordings[0], "run") if single else comparison_charts(recordings, labels)
    group = "run" if single else "compare"
    outcomes = [(label, outcome_of(r.summary)) for label, r in zip(labels, recordings, strict=True)]
    items = [("scenario", name), *outcomes] + ([("source", note)] if note else [])
    sections = [
        Section("scene-player", "Scene player", player(recordings, "player", chart_group=group, labels=labels)),
        Section("charts", "Interactive time series", charts),
        Section("what-was-run", "What was run", facts(items, "run-facts")),
    ]
    lead = "; ".join(f"{label}: {outcome}" for label, outcome in outcomes)
    return Report("view", f"vrusim view: {name}", f"{name}: {lead}.", sections, {"labels": labels})


def read_trace_recording(path: Path, scenario: Scenario) -> Recording:
    """A Recording from a trace file of `vrusim run --trace` (.csv or .parquet; `engine.trace_file.read_trace`) and
    the scenario it ran (for the road, obstacles, VRU footprints and paths, RSU); key events from the trace
    (impact: clearance ≤ 0)."""
    try:
        trace, names = read_trace(path, len(scenario.vrus))
    except UserInputError as error:
        raise UserInputError(f"SOURCE: {error}") from None
    t = trace["t_s"]
    source = trace["vru_source"]
    contact = np.flatnonzero(trace["clearance_m"] <= 0.0)

    def first(mask: np.ndarray) -> float | None:
        hits = np.flatnonzero(mask.any(axis=1)) if mask.ndim == 2 else np.flatnonzero(mask)
        return float(t[hits[0]]) if hits.size else None

    summary = {
        "scenario": scenario.name,
        "planner": scenario.planner.name,
        "v2x": scenario.v2x.enabled,
        "first_sensor_detection_s": first((source & SOURCE_SENSOR) > 0),
        "first_v2x_message_s": first((source & SOURCE_V2X) > 0),
        "collided": bool(contact.size),
        "contact_time_s": float(t[contact[0]]) if contact.size else None,
        "end_time_s": float(t[-1]),
    }
    return Recording(scenario, trace, summary, names, key_events(summary, trace))
