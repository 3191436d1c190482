"""`vrusim export SOURCE --format openscenario|commonroad --out DIR`: scenarios as files for other tools.

SOURCE is a scenario YAML file, a catalogue test id (`CPNA-25/20kph/day`), a catalogue code or prefix
(`CPNA-25`, `CPNA`: its day tests, plus night with --night) or `all` (the whole catalogue).
"""

from __future__ import annotations

from enum import StrEnum
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer
from rich.markup import escape

from vrusim.cli.options import console, user_errors
from vrusim.errors import UserInputError
from vrusim.sources import resolve_source

if TYPE_CHECKING:
    from vrusim.scenario.schema import Scenario

LISTED_FILES = 6
"""Written files are listed one per line up to this many; more are summarised."""


class ExportFormat(StrEnum):
    """Values of --format."""

    openscenario = "openscenario"
    commonroad = "commonroad"


def _check_out(out: Path) -> None:
    if out.exists() and not out.is_dir():
        raise UserInputError(f"--out: {out} is a file, expected a folder")


def _make_dir(out: Path) -> None:
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise UserInputError(f"--out: cannot create {out} ({error.strerror or error})") from None


def _export_all(scenarios: list[Scenario], fmt: ExportFormat, out: Path) -> list[Path]:
    """Write every scenario into `out` (created if missing). All documents are built before the first file is
    written, so bad input writes nothing (CommonRoad: the runs are simulated in one batch per planner)."""
    if fmt is ExportFormat.commonroad:
        from vrusim.interop.commonroad import export_commonroad_all

        _make_dir(out)
        return export_commonroad_all(scenarios, out)
    from vrusim.interop.openscenario import build_export

    exports = [build_export(scenario) for scenario in scenarios]
    if len({e.stem for e in exports}) != len(exports):
        raise UserInputError("SOURCE: two scenarios would be written to the same file name")
    _make_dir(out)
    return [path for e in exports for path in e.write(out)]


def export(
    source: Annotated[
        str,
        typer.Argument(
            metavar="SOURCE",
            help="Scenario YAML file, catalogue test id (CPNA-25/20kph/day), code or prefix (CPNA), or 'all'.",
            show_default=False,
        ),
    ],
    fmt: Annotated[
        ExportFormat,
        typer.Option("--format", case_sensitive=False, help="openscenario: .xosc + .xodr; commonroad: simulated run."),
    ],
    out: Annotated[Path, typer.Option("--out", metavar="DIR", help="Folder to write into (created if missing).")],
    night: Annotated[
        bool, typer.Option("--night", help="With a catalogue code or 'all': also the night tests.")
    ] = False,
) -> None:
    """Export scenarios for other tools: OpenSCENARIO XML with its OpenDRIVE road, or CommonRoad."""
    with user_errors():
        _check_out(out)
        scenarios = resolve_source(source, night)
        written = _export_all(scenarios, fmt, out)
    screen = console()
    if len(written) <= LISTED_FILES:
        for path in written:
            screen.print(escape(str(path)))
    screen.print(f"Exported {len(scenarios)} scenario(s) as {fmt.value}: {len(written)} files in {escape(str(out))}.")


def register(app: typer.Typer) -> None:
    """Add `vrusim export` to the app."""
    app.command("export")(export)
