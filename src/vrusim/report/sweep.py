"""Report of a sweep results folder: what was swept, collision probability with Wilson 95 % intervals overall
and per parameter (tables, interactive charts, sensitivity figures), metric statistics, and the spec
(numbers = `vrusim.sweep.summarize` over the Parquet chunks)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import yaml

from vrusim.report import figures
from vrusim.report.charts import Series, line_chart
from vrusim.report.html import Column, Html, facts, join, pre, table, tag
from vrusim.report.page import Report, Section
from vrusim.sweep.summarize import STATISTICS, SweepResults, is_numeric, open_results, summarize
from vrusim.viz.sensitivity import axis_label, sensitivity_figure

OUTCOME_COLUMNS = (
    Column("runs", "Runs"),
    Column("collisions", "Collisions"),
    Column("p", "P(collision)", 3),
    Column("p_low", "95 % low", 3),
    Column("p_high", "95 % high", 3),
    Column("stalled", "Stalled"),
    Column("incomplete", "Incomplete"),
)
"""Outcome columns of the collision tables (Wilson 95 % interval; stalled and incomplete runs)."""
GROUPABLE_TYPES = ("BOOLEAN", "VARCHAR")
"""Non-numeric DuckDB column types a report groups by (numbers always)."""


def outcome_values(group: dict[str, Any]) -> dict[str, Any]:
    """runs, collisions, p, p_low, p_high, stalled, incomplete of a summary group (or the overall summary)."""
    low, high = group["collision_probability_95"]
    return {
        "runs": group["runs"],
        "collisions": group["collisions"],
        "p": group["collision_probability"],
        "p_low": low,
        "p_high": high,
        "stalled": group["stalled"],
        "incomplete": group["incomplete"],
    }


def key_text(value: Any) -> str:
    """A group's value as shown: "low–high" for a bin, else the value."""
    if isinstance(value, dict):
        return f"{value['low']:.4g} – {value['high']:.4g}"
    if value is None:
        return "null"
    return f"{value:.6g}" if isinstance(value, float) else str(value)


def group_table(element_id: str, summary: dict[str, Any]) -> Html:
    """One row per group of one parameter: its value or bin, runs, collisions, P(collision), interval."""
    described = summary["by"][0]
    name, binned = described["name"], described["binned"]
    rows = []
    for index, group in enumerate(summary["groups"]):
        value = group["key"][name]
        cells: dict[str, Any] = {"group": key_text(value), **outcome_values(group)}
        if binned and isinstance(value, dict):
            cells |= {"bin_low": value["low"], "bin_high": value["high"]}
        else:
            cells["value"] = value
        rows.append((str(index), cells))
    first = (
        [Column("bin_low", "Bin low", 4), Column("bin_high", "Bin high", 4)] if binned else [Column("value", "Value")]
    )
    how = f"{len(described['edges']) - 1} equal-width bins" if binned else "grouped by value"
    caption = f"{axis_label(name)}: {how}; P(collision) with its Wilson 95 % interval."
    html = table(element_id, [*first, *OUTCOME_COLUMNS], rows, caption, row_header=Column("group", name))
    return Html(html.replace("<table ", f'<table data-parameter="{_attr(name)}" ', 1))


def _attr(text: str) -> str:
    from html import escape

    return escape(text, quote=True)


def probability_chart(element_id: str, summary: dict[str, Any]) -> Html | None:
    """P(collision) against a numeric parameter with the Wilson band; None for a non-numeric parameter."""
    described = summary["by"][0]
    name = described["name"]
    points = []
    for group in summary["groups"]:
        value = group["key"][name]
        x = value["centre"] if isinstance(value, dict) else value
        if isinstance(x, bool) or not isinstance(x, int | float):
            return None
        points.append((float(x), group))
    if not points:
        return None
    points.sort(key=lambda item: item[0])
    xs = [x for x, _ in points]
    groups = [g for _, g in points]
    series = Series(
        "P(collision)",
        xs,
        [g["collision_probability"] for g in groups],
        "#c62828",
        digits=3,
        band=([g["collision_probability_95"][0] for g in groups], [g["collision_probability_95"][1] for g in groups]),
        points=True,
        labels=[
            f"{g['collisions']} of {g['runs']} runs; 95 % {g['collision_probability_95'][0]:.3f}–"
            f"{g['collision_probability_95'][1]:.3f}"
            for g in groups
        ],
    )
    x_label = axis_label(name) + (" (bin centres)" if described["binned"] else "")
    return line_chart(
        element_id, f"P(collision) against {name}", x_label, "P(collision)", [series], y_range=(0.0, 1.0), x_digits=4
    )


def metrics_table(summary: dict[str, Any]) -> Html:
    """Statistics of each metric over all runs."""
    rows = [(name, {"metric": axis_label(name), **stats}) for name, stats in summary["overall"]["metrics"].items()]
    columns = [Column(stat, stat, None if stat == "count" else 4) for stat in STATISTICS]
    return table(
        "metrics",
        columns,
        rows,
        "Over all runs (p5, median, p95: linear interpolation).",
        row_header=Column("metric", "Metric"),
    )


def report_parameters(results: SweepResults) -> list[str]:
    """Parameters to group by: numbers, booleans and strings present in the chunk files."""
    return [
        name
        for name in results.groupable
        if is_numeric(results.columns[name]) or results.columns[name] in GROUPABLE_TYPES
    ]


def _what(results: SweepResults) -> list[tuple[str, Any]]:
    manifest = results.manifest
    described = "; ".join(f"{entry['name']} ({entry.get('kind', '?')})" for entry in manifest.get("parameters", []))
    return [
        ("results", str(results.directory)),
        ("sweep", str(manifest.get("name"))),
        ("base", str(manifest.get("base_file") or manifest.get("spec", {}).get("catalogue", "—"))),
        ("variants", str(manifest.get("variants"))),
        ("chunks", results.status),
        ("seed", str(manifest.get("seed"))),
        ("parameters", described or "none"),
        ("swept with vrusim", str(manifest.get("code", {}).get("vrusim", "?"))),
    ]


def sweep_report(folder: Path, bins: int = 10) -> Report:
    """The report of a sweep results folder; numeric parameters with more than `bins` values are binned."""
    results = open_results(folder)
    overall = summarize(results, bins=bins)
    names = report_parameters(results)
    by = {name: summarize(results, by=[name], bins=bins) for name in names}
    sections = [
        Section("what-was-run", "What was swept", facts(_what(results), "sweep-facts")),
        Section(
            "overall-section",
            "Collisions over all runs",
            table(
                "overall",
                OUTCOME_COLUMNS,
                [("all", outcome_values(overall["overall"]))],
                "All runs; Wilson 95 % interval.",
            ),
        ),
    ]
    for index, (name, summary) in enumerate(by.items()):
        # the interactive chart where there is one, else the static sensitivity figure (not both: same plot)
        plot = probability_chart(f"chart-by-{index}", summary) or figures.figure(
            sensitivity_figure(summary, name),
            f"Sensitivity to {name}",
            f"P(collision) against {name} with the Wilson 95 % band.",
            f"figure-by-{index}",
        )
        sections.append(Section(f"by-{index}-section", f"By {name}", join([group_table(f"by-{index}", summary), plot])))
    numeric = [name for name in names if is_numeric(results.columns[name])]
    if len(numeric) >= 2:
        pair = summarize(results, by=numeric[:2], bins=bins)
        heat = figures.figure(
            sensitivity_figure(pair, numeric[0], numeric[1]),
            "Collision probability heat map",
            f"P(collision) over {numeric[0]} and {numeric[1]}; blank: no runs.",
            "figure-heat-map",
        )
        sections.append(Section("heat-map", "Two parameters", heat))
    sections += [
        Section("metrics-section", "Metrics", metrics_table(overall)),
        Section("parameters", "Spec", spec_text(results.manifest)),
    ]
    return Report(
        kind="sweep",
        title=f"vrusim sweep: {results.manifest.get('name')}",
        lead=f"{overall['overall']['runs']} runs, {overall['overall']['collisions']} collisions ({results.status}).",
        sections=sections,
        results={"source": str(folder), "overall": overall, "by": by},
    )


def spec_text(manifest: dict[str, Any]) -> Html:
    """The sweep spec as YAML, and the parameters as planned (folded)."""
    spec = yaml.safe_dump(manifest.get("spec", {}), sort_keys=False, allow_unicode=True)
    planned = json.dumps(manifest.get("parameters", []), indent=1)
    return join(
        [
            pre(spec, "Sweep spec", open_=True),
            pre(planned, "Parameters as planned"),
            tag("p", "The base scenario of each variant is in the results folder's manifest.json.", class_="note"),
        ]
    )
