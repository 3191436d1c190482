"""`vrusim compare`: planners × V2X settings on one scenario (a YAML file, bundled scenario or catalogue test)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer
from rich import box
from rich.markup import escape
from rich.table import Table

from vrusim.cli.cells import number
from vrusim.cli.options import (
    JsonOption,
    OneSource,
    ReportOption,
    planner_names,
    planner_option,
    seed_option,
    split_names,
)
from vrusim.cli.output import console, print_json, user_errors, warn
from vrusim.cli.report import check_report_option, write_report_option

if TYPE_CHECKING:
    from vrusim.report import Report
    from vrusim.scenario.schema import Scenario

KEYS = ("Planner", "V2X")


def _planners(planner: list[str] | None, planners: str | None) -> list[str]:
    """--planner, plus the deprecated --planners (a comma list); fsm when neither is given."""
    names = planner_names(planner)
    if planners is not None:
        warn("--planners is deprecated; use --planner (repeatable, or a comma list)")
        names = list(dict.fromkeys([*names, *planner_names([planners], "--planners")]))
    return names or ["fsm"]


def _outcome_table(rows: list[dict], title: str) -> Table:
    table = Table(title=title, box=box.SIMPLE_HEAD, title_justify="left")
    for name in (*KEYS, "Collisions", "P 95 %", "Impact\nm/s", "min TTC\ns", "Sensor\ns", "V2X\ns"):
        table.add_column(name, justify="left" if name in KEYS else "right")
    for row in rows:
        low, high = row["collision_probability_95"]
        style = "red" if row["collisions"] else "green"
        table.add_row(
            escape(row["planner"]),
            escape(row["v2x"]),
            f"[{style}]{row['collisions']}/{row['runs']}[/]",
            f"{low:.2f}–{high:.2f}",
            number(row["mean_impact_speed_mps"]),
            number(row["min_ttc_s"]),
            number(row["mean_first_sensor_detection_s"]),
            number(row["mean_first_v2x_message_s"]),
        )
    return table


def _score_table(rows: list[dict]) -> Table:
    table = Table(title="Mean scores", box=box.SIMPLE_HEAD, title_justify="left")
    for name in (*KEYS, "Safety", "Efficiency", "Comfort"):
        table.add_column(name, justify="left" if name in KEYS else "right")
    for row in rows:
        table.add_row(
            escape(row["planner"]), escape(row["v2x"]), *(number(row[k]) for k in ("safety", "efficiency", "comfort"))
        )
    return table


def compare_command(
    source: OneSource,
    planner: Annotated[list[str] | None, planner_option("fsm", several=True)] = None,
    planners: Annotated[str | None, typer.Option("--planners", hidden=True, help="Deprecated: --planner.")] = None,
    v2x: Annotated[
        str,
        typer.Option(
            "--v2x",
            metavar="SETTING[,SETTING...]",
            help="V2X settings, a comma list: off, on (the scenario's own channel) or a channel profile name.",
        ),
    ] = "off,ideal",
    profiles: Annotated[
        Path | None, typer.Option("--profiles", metavar="FILE.yaml", help="Extra named channel profiles.")
    ] = None,
    seeds: Annotated[int, typer.Option("--seeds", help="Seeded variants per combination (random channels).")] = 1,
    seed: Annotated[
        int, seed_option("First seed: each combination uses seeds N, N + 1, … (--seeds of them). Default: 0.")
    ] = 0,
    as_json: JsonOption = False,
    report: ReportOption = None,
) -> None:
    """Run every planner with every V2X setting on one scenario and compare outcomes and scores; --report adds
    a scene player with one run of each combination side by side or overlaid on one timeline."""
    with user_errors():
        check_report_option(report)
        from vrusim.sources import single_source
        from vrusim.studies.compare import compare

        names = _planners(planner, planners)
        settings = split_names([v2x], "--v2x")
        base = single_source(source, catalogue_v2x=True)  # a catalogue test brings its roadside unit
        channels = _user_channels(profiles) if profiles is not None else None
        rows = compare(base, names, settings, seeds, channels, first_seed=seed)
        if report is not None:
            write_report_option(report, lambda: _report(base, rows, seeds, channels, seed), quiet=as_json)
    if as_json:
        print_json(rows)
        return
    terminal = console()
    runs = f"{seeds} seed{'s' if seeds > 1 else ''} each"
    terminal.print(_outcome_table(rows, f"{escape(base.name)}: planners × V2X ({runs})"))
    terminal.print(_score_table(rows))


def _report(base: Scenario, rows: list[dict], seeds: int, channels: dict[str, dict] | None, first_seed: int) -> Report:
    """The compare report: the rows, and one traced run (the first seed) of each combination."""
    from vrusim.report.compare import compare_report, label_of
    from vrusim.studies.compare import Combination, variant
    from vrusim.viz.recording import record

    combinations = [Combination(row["planner"], row["v2x"]) for row in rows]
    scenarios = [variant(base, c, first_seed, (channels or {}).get(c.v2x)) for c in combinations]
    recordings = [record([scenario])[0] for scenario in scenarios]  # one batch per planner and setting
    labels = [label_of(c.planner, c.v2x) for c in combinations]
    return compare_report(rows, recordings, labels, base.name, seeds)


def _user_channels(path: Path) -> dict[str, dict]:
    """Channel profiles from a YAML file, as inline specifications by name."""
    from vrusim.scenario.v2x import load_profiles

    return {name: spec.model_dump() for name, spec in load_profiles(path).items()}
