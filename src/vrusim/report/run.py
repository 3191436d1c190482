"""Report of one scenario file: what ran, the summary (= `vrusim run --json`), charts, figures, parameters."""

from __future__ import annotations

from pathlib import Path

from vrusim.metrics.outcome import outcome_of
from vrusim.report import figures
from vrusim.report.html import Column, Html, facts, join, table
from vrusim.report.page import Report, Section
from vrusim.report.parts import parameters, per_vru_table, summary_table, transitions_table
from vrusim.report.player import player
from vrusim.report.run_charts import run_charts
from vrusim.scenario.schema import Scenario
from vrusim.sources import apply_planner_and_seed, scenario_file, scenario_of
from vrusim.viz.recording import KEY_EVENT_LABELS, Recording, record


def what_was_run(scenario: Scenario, row: dict, file: Path | None) -> list[tuple[str, str]]:
    """Facts about a run: scenario, file, planner, V2X, VRUs, time step and duration."""
    items = [("scenario", scenario.name)]
    if scenario.description:
        items.append(("description", scenario.description))
    if file is not None:
        items.append(("file", str(file)))
    items += [
        ("planner", row["planner"]),
        ("V2X", "on" if row["v2x"] else "off"),
        ("VRUs", ", ".join(vru.type for vru in scenario.vrus)),
        ("time step", f"{scenario.sim.dt_s:g} s"),
        ("duration limit", f"{scenario.sim.duration_s:g} s"),
    ]
    return items


def events_table(element_id: str, recording: Recording) -> Html:
    """Key events of a run (first perception, brake onset, impact or closest approach) and their times."""
    rows = [(name, {"event": KEY_EVENT_LABELS[name], "t_s": t}) for name, t in recording.events_s.items()]
    return table(element_id, [Column("t_s", "t (s)", 3)], rows, row_header=Column("event", "Event"))


def figures_of(recordings: list[Recording], prefix: str, what: str) -> list[Html]:
    """Snapshot and time-series figures of recordings (one row / trace per recording)."""
    from vrusim.viz.snapshots import snapshot_figure
    from vrusim.viz.timeseries import timeseries_figure

    return [
        figures.figure(
            snapshot_figure(recordings),
            f"Snapshots of {what}",
            "Snapshots at key events: road, ego with heading, VRUs at their footprint, sensor sector, "
            "V2X range, planned paths and travelled trajectories.",
            f"{prefix}-snapshots",
        ),
        figures.figure(
            timeseries_figure(recordings),
            f"Time series of {what}",
            "Speed, acceleration, jerk, planner state, TTC and gap over time, with event markers.",
            f"{prefix}-timeseries",
        ),
    ]


def run_report(
    source: str | Path, v2x: bool | None = None, planner: str | None = None, seed: int | None = None
) -> Report:
    """Simulate a scenario file, a bundled scenario or one catalogue test (FSM planner; its roadside unit when V2X
    is on) with a trace and report it; V2X, planner and seed are forced when given."""
    file = scenario_file(str(source))
    scenario = apply_planner_and_seed(scenario_of(str(source), v2x, option="--v2x"), planner, seed)
    return scenario_report(scenario, file, str(source), v2x)


def scenario_report(
    scenario: Scenario, file: Path | None = None, source: str | None = None, v2x_forced: bool | None = None
) -> Report:
    """Simulate `scenario` as it is, with a trace, and report it (`file`: the file it was read from, shown as
    written; `source` and `v2x_forced` go into the results document)."""
    recording = record([scenario])[0]
    row = recording.summary
    outcome = outcome_of(row)
    sections = [
        Section("what-was-run", "What was run", facts(what_was_run(scenario, row, file), "run-facts")),
        Section(
            "summary",
            "Summary",
            join(
                [
                    summary_table("summary", row),
                    per_vru_table("per-vru", row),
                    transitions_table("transitions", row),
                    events_table("events", recording),
                ]
            ),
        ),
        Section("scene-player", "Scene player", player([recording], "player", chart_group="run")),
        Section("charts", "Interactive time series", run_charts(recording, "run")),
        Section("figures", "Figures", join(figures_of([recording], "run", scenario.name))),
        Section("parameters", "Parameters", parameters(scenario, file)),
    ]
    return Report(
        kind="run",
        title=f"vrusim run: {scenario.name}",
        lead=f"{scenario.name}: {outcome} (V2X {'on' if row['v2x'] else 'off'}, planner {row['planner']}).",
        sections=sections,
        results={"source": source if source is not None else scenario.name, "v2x_forced": v2x_forced, "row": row},
    )
