"""Pieces several report kinds share: a run's summary table and transitions, scenario parameters as YAML."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml

from vrusim.report.html import Column, Html, pre, table, tag
from vrusim.scenario.schema import Scenario
from vrusim.viz.sensitivity import unit_of

SUMMARY_LABELS = {
    "outcome": "Outcome",
    "contact_time_s": "Contact time",
    "impact_ego_speed_mps": "Impact ego speed",
    "impact_relative_speed_mps": "Impact relative speed",
    "impact_relative_longitudinal_speed_mps": "Impact relative longitudinal speed",
    "impact_side": "Impact side",
    "impact_lateral_fraction": "Impact lateral fraction",
    "first_sensor_detection_s": "First sensor detection",
    "first_v2x_message_s": "First V2X message",
    "first_warning_s": "First warning",
    "warning_ttc_s": "TTC at warning",
    "min_ttc_s": "Min TTC",
    "min_clearance_m": "Min clearance",
    "peak_accel_mps2": "Peak acceleration",
    "peak_decel_mps2": "Peak deceleration",
    "peak_jerk_mps3": "Peak jerk",
    "rms_accel_mps2": "RMS acceleration",
    "rms_jerk_mps3": "RMS jerk",
    "travel_time_s": "Travel time",
    "trip_time_s": "Trip time (scored)",
    "free_travel_time_s": "Free-flow travel time",
    "safety": "Safety score",
    "efficiency": "Efficiency score",
    "comfort": "Comfort score",
}
"""Display names of summary fields (others are shown by their field name)."""
DIGITS = 3
"""Decimals shown for numbers in the tables (the exact value is in each cell's data-value)."""


def scalar_fields(row: dict[str, Any]) -> list[str]:
    """The fields of a summary row that hold one value (not lists or mappings), labelled ones first."""
    scalars = [key for key, value in row.items() if not isinstance(value, dict | list)]
    return [key for key in SUMMARY_LABELS if key in scalars] + [key for key in scalars if key not in SUMMARY_LABELS]


def summary_table(element_id: str, row: dict[str, Any]) -> Html:
    """Every scalar field of a `vrusim run --json` row: one table row per field (data-row = field name)."""
    rows = []
    classes = {}
    for key in scalar_fields(row):
        value = row[key]
        unit = unit_of(key) or ""
        rows.append((key, {"quantity": SUMMARY_LABELS.get(key, key), "value": value, "unit": unit.split(",")[0]}))
        if key == "outcome":
            classes[(key, "value")] = "bad" if row.get("collided") else "good"
    columns = [Column("value", "Value", DIGITS), Column("unit", "Unit")]
    return table(element_id, columns, rows, row_header=Column("quantity", "Quantity"), classes=classes)


def transitions_table(element_id: str, row: dict[str, Any]) -> Html:
    """The planner's state changes of a run."""
    rows = [(str(i), item) for i, item in enumerate(row["transitions"])]
    columns = [Column("t_s", "t (s)", DIGITS), Column("from", "From"), Column("to", "To")]
    return table(element_id, columns, rows, caption="Planner state transitions" + ("" if rows else ": none"))


def scenario_yaml(scenario: Scenario) -> str:
    """The resolved scenario (every default filled in) as YAML."""
    return yaml.safe_dump(scenario.model_dump(mode="json"), sort_keys=False, allow_unicode=True)


def parameters(scenario: Scenario, file: Path | None, heading: str | None = None) -> Html:
    """The scenario file as written (open) and the resolved scenario (folded)."""
    parts = [tag("h3", heading) if heading else None]
    if file is not None and file.is_file():
        parts.append(pre(file.read_text(encoding="utf-8"), f"{file.name} as written", open_=True))
    parts.append(pre(scenario_yaml(scenario), "Resolved scenario (all defaults filled in)"))
    return tag("div", *parts, class_="parameters")
