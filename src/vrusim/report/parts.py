"""Pieces several report kinds share: a run's summary table and transitions, scenario parameters as YAML."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from vrusim.metrics.catalog import get_metric, metrics
from vrusim.report.html import Column, Html, pre, table, tag
from vrusim.scenario import yaml_text
from vrusim.scenario.schema import Scenario
from vrusim.viz.sensitivity import unit_of

DIGITS = 3
"""Decimals shown for numbers in the tables (the exact value is in each cell's data-value)."""


def metric_column(name: str, digits: int | None = None) -> Column:
    """A table column of a metric, headed by its catalogue label and unit ("Min TTC (s)")."""
    metric = get_metric(name)
    return Column(name, f"{metric.label} ({metric.unit})" if metric.unit else metric.label, digits)


def scalar_fields(row: dict[str, Any]) -> list[str]:
    """The fields of a summary row that hold one value (not lists or mappings): the metrics in catalogue order,
    then the others (what ran) in row order."""
    scalars = [key for key, value in row.items() if not isinstance(value, dict | list)]
    names = [m.name for m in metrics() if m.name in scalars]
    return names + [key for key in scalars if key not in names]


def summary_table(element_id: str, row: dict[str, Any]) -> Html:
    """Every scalar field of a `vrusim run --json` row: one table row per field (data-row = field name), metrics
    labelled by the catalogue (`vrusim.metrics.catalog`)."""
    catalogue = {m.name: m for m in metrics()}
    rows = []
    classes = {}
    for key in scalar_fields(row):
        metric = catalogue.get(key)
        label, unit = (metric.label, metric.unit) if metric else (key, (unit_of(key) or "").split(",")[0])
        rows.append((key, {"quantity": label, "value": row[key], "unit": unit}))
        if key == "outcome":
            classes[(key, "value")] = "bad" if row.get("collided") else "good"
    columns = [Column("value", "Value", DIGITS), Column("unit", "Unit")]
    return table(element_id, columns, rows, row_header=Column("quantity", "Quantity"), classes=classes)


def per_vru_metrics(row: dict[str, Any]) -> list[str]:
    """The metrics of a summary row that hold one number per VRU (`min_ttc_per_vru_s`, ...), in catalogue order."""
    return [
        m.name
        for m in metrics()
        if m.split is not None
        and isinstance(row.get(m.name), list)
        and all(v is None or isinstance(v, int | float) for v in row[m.name])
    ]


def per_vru_table(element_id: str, row: dict[str, Any]) -> Html:
    """The per-VRU metrics of a run: one table row per VRU slot (data-row = slot), one column per metric."""
    names = per_vru_metrics(row)
    count = max((len(row[name]) for name in names), default=0)
    rows = [(str(k), {"vru": k, **{name: row[name][k] for name in names}}) for k in range(count)]
    columns = [metric_column(name, DIGITS) for name in names]
    return table(element_id, columns, rows, caption="Per-VRU minima", row_header=Column("vru", "VRU slot"))


def transitions_table(element_id: str, row: dict[str, Any]) -> Html:
    """The planner's state changes of a run."""
    rows = [(str(i), item) for i, item in enumerate(row["transitions"])]
    columns = [Column("t_s", "t (s)", DIGITS), Column("from", "From"), Column("to", "To")]
    return table(element_id, columns, rows, caption="Planner state transitions" + ("" if rows else ": none"))


def scenario_yaml(scenario: Scenario) -> str:
    """The resolved scenario (every default filled in) as YAML."""
    return yaml_text.scenario_yaml(scenario.model_dump(mode="json"))


def parameters(scenario: Scenario, file: Path | None, heading: str | None = None) -> Html:
    """The scenario file as written (open) and the resolved scenario (folded)."""
    parts = [tag("h3", heading) if heading else None]
    if file is not None and file.is_file():
        parts.append(pre(file.read_text(encoding="utf-8"), f"{file.name} as written", open_=True))
    parts.append(pre(scenario_yaml(scenario), "Resolved scenario (all defaults filled in)"))
    return tag("div", *parts, class_="parameters")
