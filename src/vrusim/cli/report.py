"""`vrusim report SOURCE --out REPORT.html`: one self-contained HTML report of a run, the paper reproduction,
a `vrusim ncap --out` folder or a sweep results folder."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer
from rich.markup import escape

from vrusim.cli.options import (
    JsonOption,
    V2XSwitch,
    one_planner,
    planner_option,
    seed_option,
    switch_value,
    v2x_switch_option,
)
from vrusim.cli.output import console, print_json, user_errors
from vrusim.errors import UserInputError
from vrusim.io.paths import check_output_file

if TYPE_CHECKING:
    from vrusim.report import Report

RUN_ONLY = "Scenario or catalogue test only: "


def report_command(
    source: Annotated[
        str,
        typer.Argument(
            metavar="SOURCE",
            help="A scenario .yaml file, a bundled scenario or a catalogue test id (run here), the word 'paper', a "
            "`vrusim ncap --out` folder, or a sweep results folder (with manifest.json).",
            show_default=False,
        ),
    ],
    out: Annotated[
        Path, typer.Option("--out", metavar="REPORT.html", help="The HTML file to write (replaced if it exists).")
    ],
    planner: Annotated[
        list[str] | None, planner_option("the scenario file's (fsm for a catalogue test); scenarios only")
    ] = None,
    v2x: Annotated[V2XSwitch | None, v2x_switch_option(RUN_ONLY + "force V2X on or off.")] = None,
    seed: Annotated[int | None, seed_option(RUN_ONLY + "key of the run's random numbers.")] = None,
    bins: Annotated[
        int, typer.Option("--bins", help="Sweep only: numeric parameters with more values are cut into this many bins.")
    ] = 10,
    player: Annotated[
        list[str] | None,
        typer.Option(
            "--player",
            metavar="TEST-ID",
            help="ncap folder only: add a scene player of this test, run again as assessed (repeatable).",
        ),
    ] = None,
    as_json: JsonOption = False,
) -> None:
    """Write one self-contained HTML report (tables, figures, interactive charts, parameters, code version)."""
    with user_errors():
        from vrusim.report import build_report, check_output, source_kind, write_report

        chosen = one_planner(planner, "report")
        source_kind(source)
        check_output(check_output_file(out, "--out"))
        if bins < 1:
            raise UserInputError(f"--bins: expected a whole number ≥ 1, got {bins}")
        report = build_report(source, switch_value(v2x), bins, chosen, seed, player or ())
        size = write_report(report, out)
    if as_json:
        print_json({"out": str(out), "kind": report.kind, "bytes": size})
        return
    console().print(f"Wrote {escape(str(out))} ({report.kind} report, {size / 1024:.0f} KiB).")


def check_report_option(report_path: Path | None) -> None:
    """`--report OUT.html` of other commands: refuse a bad path before anything runs."""
    if report_path is not None:
        from vrusim.report import check_output

        check_output(check_output_file(report_path, "--report"), "--report")


def write_report_option(report_path: Path | None, build: Callable[[], Report], quiet: bool = False) -> None:
    """`--report OUT.html` of other commands: write the report `build()` returns (atomically); say so on stdout
    unless `quiet` (the command prints JSON)."""
    if report_path is None:
        return
    from vrusim.report import write_report

    size = write_report(build(), report_path, "--report")
    if not quiet:
        console().print(f"Wrote {escape(str(report_path))} ({size / 1024:.0f} KiB).")
