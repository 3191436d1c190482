"""The `vrusim` command line: run a scenario file, or reproduce the paper's case studies.

    vrusim run FILE.yaml [--v2x on|off] [--json] [--trace OUT.csv|OUT.parquet]
                         [--plot OUT.png|.svg|.pdf] [--animate OUT.gif|.mp4]
    vrusim paper [--json] [--figures DIR]
    vrusim list | ncap | compare | sweep | summarize | report | export ...   (see `vrusim COMMAND --help`)
    vrusim --version

Bad input (a scenario field, a file, an option) ends with one message on stderr naming the culprit and exit
code 2, never a traceback; anything else that goes wrong is a bug and keeps its traceback.
"""

from __future__ import annotations

import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Annotated

import typer
from pydantic import ValidationError
from rich import box
from rich.markup import escape
from rich.table import Table

from vrusim.cli.compare import register as register_compare_command
from vrusim.cli.export import register as register_export_command
from vrusim.cli.figures import check_figures_dir, check_run_outputs, write_paper_figures, write_run_outputs
from vrusim.cli.ncap import register as register_catalogue_commands
from vrusim.cli.options import USER_ERROR_EXIT_CODE, OneSource, V2XSwitch, print_json, report_user_error, user_errors
from vrusim.cli.options import console as _console
from vrusim.cli.report import register as register_report_command
from vrusim.cli.report import write_report_option
from vrusim.cli.summarize import register as register_summarize_command
from vrusim.cli.sweep import register as register_sweep_command
from vrusim.errors import UserInputError
from vrusim.version import __version__

app = typer.Typer(
    name="vrusim",
    help="Closed-loop simulation of Euro NCAP vulnerable-road-user tests with perception, V2X and planners.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_show_locals=False,
)


# ----------------------------------------------------------------------------------------------- helpers


def _num(value: float | None, unit: str = "", digits: int = 2) -> str:
    if value is None:
        return "—"
    text = f"{value:.{digits}f}"
    return f"{text} {unit}" if unit else text


def _mark(ok: bool) -> str:
    return "[green]✓[/]" if ok else "[red]✗[/]"


def _on_off(enabled: bool) -> str:
    return "on" if enabled else "off"


def _version_callback(value: bool) -> None:
    if value:
        typer.echo(f"vrusim {__version__}")
        raise typer.Exit()


@app.callback()
def _root(
    version: Annotated[
        bool,
        typer.Option("--version", help="Print the version and exit.", callback=_version_callback, is_eager=True),
    ] = False,
) -> None:
    """Closed-loop simulation of Euro NCAP vulnerable-road-user tests with perception, V2X and planners."""


# ----------------------------------------------------------------------------------------------- vrusim run


def _apply_v2x(scenario, switch: V2XSwitch, file: Path):
    """The scenario with V2X forced on or off; a scenario that cannot take it is a user error naming --v2x."""
    try:
        return scenario.with_v2x(switch is V2XSwitch.on)
    except ValidationError as error:
        from vrusim.scenario.loading import describe_validation_error

        raise UserInputError(describe_validation_error(error, f"{file} with --v2x {switch.value}")) from None


def _run_scenario(source: str, v2x: V2XSwitch | None):
    """The one scenario `vrusim run` simulates: a file (V2X as in it unless forced) or one catalogue test (FSM
    planner; with `--v2x on` the catalogue's roadside unit)."""
    from vrusim.sources import is_scenario_file, single_source

    scenario = single_source(source, catalogue_v2x=v2x is V2XSwitch.on)
    if v2x is None or not is_scenario_file(source):
        return scenario
    return _apply_v2x(scenario, v2x, Path(source))


def _summary_table(row: dict) -> Table:
    title = f"{escape(row['scenario'])}  ·  V2X {_on_off(row['v2x'])}  ·  planner {escape(row['planner'])}"
    table = Table(title=title, show_header=False, box=box.SIMPLE_HEAD, title_justify="left")
    table.add_column("quantity", style="bold")
    table.add_column("value")
    collided = row["collided"]
    table.add_row("Outcome", "[bold red]COLLISION[/]" if collided else "[bold green]avoided[/]", end_section=True)

    table.add_row("Contact time", _num(row["contact_time_s"], "s"))
    table.add_row("Impact ego speed", _num(row["impact_ego_speed_mps"], "m/s"))
    relative = _num(row["impact_relative_speed_mps"], "m/s")
    if row["impact_relative_longitudinal_speed_mps"] is not None:
        relative += f" (longitudinal {_num(row['impact_relative_longitudinal_speed_mps'], 'm/s')})"
    table.add_row("Impact relative speed", relative)
    side = "—"
    if row["impact_side"] is not None:
        side = f"{row['impact_side']}, lateral fraction {_num(row['impact_lateral_fraction'])}"
    table.add_row("Impact side", side, end_section=True)

    table.add_row("First sensor detection", _num(row["first_sensor_detection_s"], "s"))
    table.add_row("First V2X message", _num(row["first_v2x_message_s"], "s"))
    transitions = [
        f"{_num(item['t_s'], 's')}  {escape(item['from'])} → {escape(item['to'])}" for item in row["transitions"]
    ]
    table.add_row("Planner transitions", "\n".join(transitions) if transitions else "none", end_section=True)

    table.add_row("Min TTC", _num(row["min_ttc_s"], "s"))
    table.add_row("Min clearance", _num(row["min_clearance_m"], "m"))
    table.add_row(
        "Peak accel / decel",
        f"{_num(row['peak_accel_mps2'])} / {_num(row['peak_decel_mps2'])} m/s²",
    )
    table.add_row("Peak jerk", _num(row["peak_jerk_mps3"], "m/s³"))
    table.add_row("RMS accel", _num(row["rms_accel_mps2"], "m/s²"))
    table.add_row("RMS jerk", _num(row["rms_jerk_mps3"], "m/s³"))
    free = _num(row["free_travel_time_s"], "s")
    if row["travel_time_s"] is not None:
        travel = f"{_num(row['travel_time_s'], 's')} (free flow {free})"
    else:
        travel = f"route not completed (trip time counted as {_num(row['trip_time_s'], 's')}, free flow {free})"
    table.add_row("Travel time", travel, end_section=True)

    table.add_row("Safety score", _num(row["safety"]))
    table.add_row("Efficiency score", _num(row["efficiency"]))
    table.add_row("Comfort score", _num(row["comfort"]))
    return table


@app.command()
def run(
    source: OneSource,
    v2x: Annotated[
        V2XSwitch | None,
        typer.Option(
            "--v2x",
            case_sensitive=False,
            help="Force V2X on or off (default: as in the file; off for a catalogue test).",
        ),
    ] = None,
    as_json: Annotated[
        bool, typer.Option("--json", help="Print the summary as one JSON document and nothing else.")
    ] = False,
    trace: Annotated[
        Path | None,
        typer.Option(
            "--trace",
            metavar="OUT.csv|OUT.parquet",
            help="Also write the per-step trace (format from the suffix: .csv or .parquet).",
            show_default=False,
        ),
    ] = None,
    plot: Annotated[
        Path | None,
        typer.Option(
            "--plot",
            metavar="OUT.png|OUT.svg|OUT.pdf",
            help="Also write one figure: snapshots at the key events above the time series (docs/figures.md).",
            show_default=False,
        ),
    ] = None,
    animate: Annotated[
        Path | None,
        typer.Option(
            "--animate",
            metavar="OUT.gif|OUT.mp4",
            help="Also write an animation of the run, 25 frames per second of simulated time.",
            show_default=False,
        ),
    ] = None,
) -> None:
    """Simulate one scenario (a YAML file or a catalogue test) and print its summary."""
    with user_errors():
        from vrusim.engine.simulate import simulate
        from vrusim.engine.trace_file import check_trace_path, write_trace
        from vrusim.metrics.summary import summary_rows

        if trace is not None:
            try:
                check_trace_path(trace)
            except UserInputError as error:
                raise UserInputError(f"--trace: {error}") from None
        check_run_outputs(plot, animate)
        scenario = _run_scenario(source, v2x)
        pictures = plot is not None or animate is not None
        result = simulate([scenario], trace=trace is not None or pictures)
        row = summary_rows(result)[0]
        rows_written = None
        if trace is not None:
            try:
                rows_written = write_trace(result, trace)
            except UserInputError as error:
                raise UserInputError(f"--trace: {error}") from None
        written = write_run_outputs(result, plot, animate) if pictures else []
    if as_json:
        print_json(row)
        return
    console = _console()
    console.print(_summary_table(row))
    if trace is not None:
        console.print(f"Trace written to {escape(str(trace))} ({rows_written} steps).")
    for line in written:
        console.print(escape(line))


# ----------------------------------------------------------------------------------------------- vrusim paper


def _difference(ours: float, paper: float) -> float:
    """ours - paper rounded for display (never "-0.00")."""
    return round(ours - paper, 2) + 0.0


def _score_cell(paper: float, ours: float, tolerance: float) -> str:
    colour = "green" if abs(ours - paper) <= tolerance + 1e-9 else "red"
    return f"{paper:.2f}→{ours:.2f} [{colour}]{_difference(ours, paper):+.2f}[/]"


def _outcome(collision: bool) -> str:
    return "collision" if collision else "avoided"


def _table_ii(result: dict) -> Table:
    tolerance = result["tolerances"]["score"]
    table = Table(
        title=f"Table II — scores paper→ours and difference (✓: all three within ±{tolerance:.2f})",
        box=box.SIMPLE_HEAD,
        pad_edge=False,
    )
    table.add_column("Case", no_wrap=True)
    table.add_column("V2X")
    table.add_column("Outcome\npaper", no_wrap=True)
    table.add_column("Outcome\nours", no_wrap=True)
    for name in ("Safety", "Efficiency", "Comfort"):
        table.add_column(f"{name}\npaper→ours Δ", justify="right", no_wrap=True)
    table.add_column(f"±{tolerance:.2f}", justify="center")
    for case in result["cases"]:
        paper, ours = case["paper"], case["ours"]
        colour = "green" if case["outcome_matches"] else "red"
        table.add_row(
            escape(case["title"]),
            _on_off(case["v2x"]),
            _outcome(paper["collision"]),
            f"[{colour}]{_outcome(ours['collided'])}[/]",
            *(_score_cell(paper[name], ours[name], tolerance) for name in ("safety", "efficiency", "comfort")),
            _mark(case["scores_within_tolerance"]),
        )
    return table


def _events_table(result: dict) -> Table:
    tolerance = result["tolerances"]["time_s"]
    titles = {case["case"]: case["title"] for case in result["cases"]}
    table = Table(title=f"Event times from the figure captions (✓ within ±{tolerance:.1f} s)", box=box.SIMPLE_HEAD)
    table.add_column("Case", no_wrap=True)
    table.add_column("V2X")
    table.add_column("Event")
    table.add_column("Paper (s)", justify="right")
    table.add_column("Ours (s)", justify="right")
    table.add_column("Δ (s)", justify="right")
    table.add_column(f"±{tolerance:.1f} s", justify="center")
    for event in result["events"]:
        ours = event["ours_s"]
        table.add_row(
            escape(titles.get(event["case"], event["case"])),
            _on_off(event["v2x"]),
            escape(event["event"]),
            _num(event["paper_s"]),
            _num(ours),
            "—" if ours is None else f"{_difference(ours, event['paper_s']):+.2f}",
            _mark(event["within_tolerance"]),
        )
    return table


@app.command()
def paper(
    as_json: Annotated[
        bool, typer.Option("--json", help="Print the comparison as one JSON document and nothing else.")
    ] = False,
    report: Annotated[
        Path | None,
        typer.Option(
            "--report", metavar="OUT.html", help="Also write a self-contained HTML report.", show_default=False
        ),
    ] = None,
    figures: Annotated[
        Path | None,
        typer.Option(
            "--figures",
            metavar="DIR",
            help="Also write per case a snapshot figure (rows V2X off / on) and a time-series figure as PNGs.",
            show_default=False,
        ),
    ] = None,
) -> None:
    """Reproduce the paper's three case studies (V2X off and on) and compare with its published results."""
    with user_errors():
        from vrusim.paper.cases import match_counts, reproduce

        if report is not None:
            from vrusim.report import check_output

            check_output(report, "--report")
        if figures is not None:
            check_figures_dir(figures)
        result = reproduce()
        figure_files = write_paper_figures(figures) if figures is not None else []
        if report is not None:
            from vrusim.report.paper import paper_report

            write_report_option(report, lambda: paper_report(result), quiet=as_json)
    if as_json:
        print_json(result)
        return
    console = _console()
    console.print(_table_ii(result))
    console.print(_events_table(result))
    if figure_files:
        console.print(f"Figures written to {escape(str(figures))}: {', '.join(f.name for f in figure_files)}.")
    counts = match_counts(result)
    all_match = all(ok == total for ok, total in counts.values())
    parts = ", ".join(f"{ok}/{total} {name}" for name, (ok, total) in counts.items())
    colour = "green" if all_match else "yellow"
    console.print(f"[{colour}]Matches: {parts}.[/]")
    if not all_match:
        console.print('Where and why we differ from the paper: docs/paper.md, section "Where we differ, and why".')


register_catalogue_commands(app)
register_compare_command(app)
register_sweep_command(app)
register_summarize_command(app)
register_report_command(app)
register_export_command(app)

# ----------------------------------------------------------------------------------------------- entry point


def main(argv: Sequence[str] | None = None, prog_name: str = "vrusim") -> None:
    """Console-script entry point: run the app; any UserInputError becomes its message and exit code 2."""
    try:
        app(args=None if argv is None else list(argv), prog_name=prog_name)
    except UserInputError as error:
        report_user_error(error)
        sys.exit(USER_ERROR_EXIT_CODE)
