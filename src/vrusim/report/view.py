"""The page of `vrusim view`: the scene player of one run or of several compared (V2X off / on), with its linked
charts; and a Recording read back from a saved trace file (`vrusim run --trace`) plus the scenario it ran."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

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

TRACE_SOURCE_SUFFIXES = (".csv", ".parquet")
"""A SOURCE ending in one of these is a saved trace (`vrusim run --trace`)."""


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


def _column(table: dict[str, list], name: str, path: Path) -> np.ndarray:
    if name not in table:
        raise UserInputError(f"SOURCE: {path} has no column {name!r}; expected a trace written by `vrusim run --trace`")
    return np.array([np.nan if v is None else v for v in table[name]], dtype=float)


def read_trace_recording(path: Path, scenario: Scenario) -> Recording:
    """A Recording from a trace file of `vrusim run --trace` (.csv or .parquet) and the scenario it ran (for the
    road, obstacles, VRU footprints and paths, RSU); key events from the trace (impact: clearance ≤ 0)."""
    import pyarrow as pa
    import pyarrow.csv as pa_csv
    import pyarrow.parquet as pq

    try:
        data = pq.read_table(path) if path.suffix.lower() == ".parquet" else pa_csv.read_csv(path)
    except (OSError, pa.ArrowException) as error:
        raise UserInputError(f"SOURCE: cannot read trace {path} ({error})") from None
    table = data.to_pydict()
    n_vrus = len(scenario.vrus)
    if any(f"vru{k}_x_m" not in table for k in range(n_vrus)):
        raise UserInputError(f"--scenario: its {n_vrus} VRUs do not match the trace {path} (no vru{{k}}_x_m columns)")
    if not table.get("t_s"):
        raise UserInputError(f"SOURCE: {path} holds no trace rows")
    heading = np.radians(_column(table, "ego_heading_deg", path))
    names = list(dict.fromkeys(str(m) for m in table.get("planner_mode", [])))
    trace: dict[str, np.ndarray] = {
        "t_s": _column(table, "t_s", path),
        "ego_heading_x": np.cos(heading),
        "ego_heading_y": np.sin(heading),
        "planner_mode": np.array([names.index(str(m)) for m in table["planner_mode"]], dtype=np.int8),
    }
    for name in ("ego_x_m", "ego_y_m", "ego_speed_mps", "ego_accel_mps2", "ego_command_mps2", "clearance_m"):
        trace[name] = _column(table, name, path)
    ttc = _column(table, "ttc_s", path)
    trace["ttc_s"] = np.where(np.isnan(ttc), np.inf, ttc)
    for column, field in (("x_m", "vru_x_m"), ("y_m", "vru_y_m"), ("speed_mps", "vru_speed_mps")):
        trace[field] = np.stack([_column(table, f"vru{k}_{column}", path) for k in range(n_vrus)], axis=1)
    trace["vru_source"] = np.stack(
        [_column(table, f"vru{k}_source", path).astype(np.int8) for k in range(n_vrus)], axis=1
    )
    rows = len(trace["t_s"])
    trace["vru_v2x_age_s"] = np.stack(  # traces written before the column existed have none: no message age
        [
            _column(table, f"vru{k}_v2x_age_s", path) if f"vru{k}_v2x_age_s" in table else np.full(rows, np.nan)
            for k in range(n_vrus)
        ],
        axis=1,
    )
    t = trace["t_s"]
    source = trace["vru_source"]
    contact = np.flatnonzero(trace["clearance_m"] <= 0.0)

    def first(mask: np.ndarray) -> float | None:
        rows = np.flatnonzero(mask.any(axis=1)) if mask.ndim == 2 else np.flatnonzero(mask)
        return float(t[rows[0]]) if rows.size else None

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
    return Recording(scenario, trace, summary, tuple(names), key_events(summary, trace))
