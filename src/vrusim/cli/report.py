"""`vrusim report SOURCE --out REPORT.html`: one self-contained HTML report of a run, the paper reproduction,
a `vrusim ncap --out` folder or a sweep results folder."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer
from rich.markup import escape

from vrusim.cli.options import V2XSwitch, console, user_errors
from vrusim.errors import UserInputError

if TYPE_CHECKING:
    from vrusim.report import Report


def report_command(
    source: Annotated[
        str,
        typer.Argument(
            metavar="SOURCE",
            help="A scenario .yaml file (run here), the word 'paper', a `vrusim ncap --out` folder, or a sweep "
            "results folder (with manifest.json).",
            show_default=False,
        ),
    ],
    out: Annotated[Path, typer.Option("--out", metavar="REPORT.html", help="The HTML file to write.")],
    v2x: Annotated[
        V2XSwitch | None,
        typer.Option("--v2x", case_sensitive=False, help="Scenario file only: force V2X on or off."),
    ] = None,
    bins: Annotated[
        int, typer.Option("--bins", help="Sweep only: numeric parameters with more values are cut into this many bins.")
    ] = 10,
) -> None:
    """Write one self-contained HTML report (tables, figures, interactive charts, parameters, code version)."""
    with user_errors():
        from vrusim.report import build_report, check_output, source_kind, write_report

        source_kind(source)
        check_output(out)
        if bins < 1:
            raise UserInputError(f"--bins: expected a whole number ≥ 1, got {bins}")
        report = build_report(source, None if v2x is None else v2x is V2XSwitch.on, bins)
        size = write_report(report, out)
    console().print(f"Wrote {escape(str(out))} ({report.kind} report, {size / 1024:.0f} KiB).")


def write_report_option(report_path: Path | None, build: Callable[[], Report], quiet: bool = False) -> None:
    """`--report OUT.html` of other commands: write the report `build()` returns (atomically); say so on stdout
    unless `quiet` (the command prints JSON)."""
    if report_path is None:
        return
    from vrusim.report import write_report

    size = write_report(build(), report_path, "--report")
    if not quiet:
        console().print(f"Wrote {escape(str(report_path))} ({size / 1024:.0f} KiB).")


def register(app: typer.Typer) -> None:
    """Add `vrusim report` to the app."""
    app.command("report")(report_command)
