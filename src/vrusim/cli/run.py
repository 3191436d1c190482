"""`vrusim run SOURCE`: simulate one scenario and print its summary (optionally its trace, figure, animation)."""

from __future__ import annotations

from functools import partial
from pathlib import Path
from typing import Annotated

from rich import box
from rich.markup import escape
from rich.table import Table

from vrusim.cli.cells import on_off
from vrusim.cli.figures import check_run_outputs, write_run_outputs
from vrusim.cli.options import (
    JsonOption,
    LenientOption,
    OneSource,
    ReportOption,
    V2XSwitch,
    file_option,
    one_planner,
    planner_option,
    seed_option,
    switch_value,
    v2x_switch_option,
)
from vrusim.cli.output import console, named_errors, print_json, user_errors
from vrusim.cli.report import check_report_option, write_report_option
from vrusim.errors import UserInputError


def _summary_table(row: dict) -> Table:
    """The summary of one run as two columns, quantity and value, in sections (`vrusim.metrics.display`)."""
    from vrusim.metrics.display import display_rows

    title = f"{escape(row['scenario'])}  ·  V2X {on_off(row['v2x'])}  ·  planner {escape(row['planner'])}"
    table = Table(title=title, show_header=False, box=box.SIMPLE_HEAD, title_justify="left")
    table.add_column("quantity", style="bold")
    table.add_column("value")
    for line in display_rows(row):
        table.add_row(line.label, line.text, end_section=line.end_section)
    return table


def run_command(
    source: OneSource,
    planner: Annotated[list[str] | None, planner_option("the scenario file's (fsm for a catalogue test)")] = None,
    v2x: Annotated[
        V2XSwitch | None,
        v2x_switch_option("Force V2X on or off (default: as in the file; off for a catalogue test)."),
    ] = None,
    seed: Annotated[
        int | None, seed_option("Key of the run's random numbers (sensor noise, V2X loss). Default: the file's.")
    ] = None,
    lenient: LenientOption = False,
    as_json: JsonOption = False,
    trace: Annotated[
        Path | None,
        file_option(
            "--trace", "OUT.csv|OUT.parquet", "Also write the per-step trace (format by suffix: .csv or .parquet)."
        ),
    ] = None,
    plot: Annotated[
        Path | None,
        file_option(
            "--plot",
            "OUT.png|OUT.svg|OUT.pdf",
            "Also write one figure: snapshots at the key events above the time series (docs/figures.md).",
        ),
    ] = None,
    animate: Annotated[
        Path | None,
        file_option(
            "--animate", "OUT.gif|OUT.mp4", "Also write an animation of the run, 25 frames per simulated second."
        ),
    ] = None,
    report: ReportOption = None,
) -> None:
    """Simulate one scenario (a YAML file, a bundled scenario or a catalogue test) and print its summary."""
    with user_errors():
        from vrusim.engine.simulate import simulate
        from vrusim.metrics.summary import summary_rows
        from vrusim.sources import apply_planner_and_seed, scenario_of

        chosen = one_planner(planner, "run")
        if trace is not None:
            from vrusim.engine.trace_file import check_trace_path  # imports pyarrow: only for --trace
            from vrusim.io.paths import check_output_file

            check_output_file(trace, "--trace")
            with named_errors("--trace"):
                check_trace_path(trace)
        check_run_outputs(plot, animate)
        check_report_option(report)
        given: object = source
        if str(source).lower().endswith(".xosc"):
            from vrusim.cli.importing import imported_scenario

            given = imported_scenario(Path(source), lenient)
        elif lenient:
            raise UserInputError("--lenient: only for an OpenSCENARIO SOURCE (.xosc)")
        scenario = apply_planner_and_seed(scenario_of(given, switch_value(v2x), option="--v2x"), chosen, seed)
        pictures = plot is not None or animate is not None
        result = simulate([scenario], trace=trace is not None or pictures)
        row = summary_rows(result)[0]
        rows_written = None
        if trace is not None:
            from vrusim.engine.trace_file import write_trace

            with named_errors("--trace"):
                rows_written = write_trace(result, trace)
        written = write_run_outputs(result, scenario, plot, animate) if pictures else []
        if report is not None:
            from vrusim.report.run import scenario_report
            from vrusim.sources import scenario_file

            file = None if str(source).lower().endswith(".xosc") else scenario_file(source)
            build = partial(scenario_report, scenario, file, source, switch_value(v2x))
            write_report_option(report, build, quiet=as_json)
    if as_json:
        print_json(row)
        return
    terminal = console()
    terminal.print(_summary_table(row))
    if trace is not None:
        terminal.print(f"Trace written to {escape(str(trace))} ({rows_written} steps).")
    for line in written:
        terminal.print(escape(line))
