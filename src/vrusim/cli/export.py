"""`vrusim export SOURCE --format openscenario|commonroad --out DIR`: scenarios as files for other tools.

SOURCE is a scenario YAML file, a bundled scenario (`paper:pedestrian`), a catalogue test id
(`CPNA-25/20kph/day`), a catalogue code or prefix (`CPNA-25`, `CPNA`: its day tests, plus night with --night) or
`all` (the whole catalogue).
"""

from __future__ import annotations

from enum import StrEnum
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer
from rich.markup import escape

from vrusim.cli.options import ForceOption, JsonOption, check_out_dir, out_dir_option
from vrusim.cli.output import console, print_json, user_errors
from vrusim.errors import UserInputError
from vrusim.io.paths import for_option, new_folder

if TYPE_CHECKING:
    from vrusim.scenario.schema import Scenario

LISTED_FILES = 6
"""Written files are listed one per line up to this many; more are summarised."""


class ExportFormat(StrEnum):
    """Values of --format."""

    openscenario = "openscenario"
    commonroad = "commonroad"


def _export_all(scenarios: list[Scenario], fmt: ExportFormat, out: Path) -> list[Path]:
    """Write every scenario into the folder `out`. All documents are built before the first file is written, so
    bad input writes nothing (CommonRoad: the runs are simulated in one batch per planner)."""
    if fmt is ExportFormat.commonroad:
        from vrusim.interop.commonroad import export_commonroad_all

        with new_folder(out, "--out"), for_option("--out"):
            return export_commonroad_all(scenarios, out)
    from vrusim.interop.openscenario import build_export

    exports = [build_export(scenario) for scenario in scenarios]
    if len({e.stem for e in exports}) != len(exports):
        raise UserInputError("SOURCE: two scenarios would be written to the same file name")
    with new_folder(out, "--out"), for_option("--out"):
        return [path for e in exports for path in e.write(out)]


def export_command(
    source: Annotated[
        str,
        typer.Argument(
            metavar="SOURCE",
            help="Scenario YAML file, bundled scenario (paper:pedestrian), catalogue test id (CPNA-25/20kph/day), "
            "code or prefix (CPNA), or 'all'.",
            show_default=False,
        ),
    ],
    fmt: Annotated[
        ExportFormat,
        typer.Option("--format", case_sensitive=False, help="openscenario: .xosc + .xodr; commonroad: simulated run."),
    ],
    out: Annotated[Path, out_dir_option("the exported files")],
    force: ForceOption = False,
    night: Annotated[
        bool,
        typer.Option("--night", help="With a catalogue code or 'all': also the night tests (not for a scenario file)."),
    ] = False,
    as_json: JsonOption = False,
) -> None:
    """Export scenarios for other tools: OpenSCENARIO XML with its OpenDRIVE road, or CommonRoad."""
    from vrusim.sources import resolve_source, scenario_file

    with user_errors():
        if night and scenario_file(source) is not None:
            raise UserInputError("--night: only for catalogue tests (a code or prefix, or 'all'), not a scenario file")
        check_out_dir(out, force)
        scenarios = resolve_source(source, night)
        written = _export_all(scenarios, fmt, out)
    if as_json:
        print_json({"format": fmt.value, "scenarios": len(scenarios), "files": [str(path) for path in written]})
        return
    screen = console()
    if len(written) <= LISTED_FILES:
        for path in written:
            screen.print(escape(str(path)))
    scenarios_text = f"{len(scenarios)} scenario" + ("" if len(scenarios) == 1 else "s")
    files_text = f"{len(written)} file" + ("" if len(written) == 1 else "s")
    screen.print(f"Exported {scenarios_text} as {fmt.value}: {files_text} in {escape(str(out))}.")
