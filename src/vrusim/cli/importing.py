"""`vrusim import FILE.xosc --out SCENARIO.yaml`: an OpenSCENARIO file (vrusim's export subset) as a scenario YAML.

The road file its `<LogicFile>` names is read from next to it. The YAML holds the fields that differ from
vrusim's defaults; the planner, sensor, V2X and time step are not in an OpenSCENARIO file and keep the defaults.
`vrusim run FILE.xosc` runs such a file directly. Supported elements: docs/openscenario_import.md.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer
from rich.markup import escape

from vrusim.cli.options import JsonOption, LenientOption, file_option
from vrusim.cli.output import console, print_json, user_errors
from vrusim.errors import UserInputError
from vrusim.io.paths import check_not_input, check_output_file
from vrusim.version import __version__

if TYPE_CHECKING:
    from vrusim.scenario.schema import Scenario


def scenario_yaml_text(scenario: Scenario, source: str) -> str:
    """The scenario as YAML (fields that differ from the defaults), under a comment naming where it came from."""
    from vrusim.scenario.yaml_text import scenario_yaml

    body = scenario_yaml(scenario.model_dump(mode="json", exclude_defaults=True))
    head = f"# Imported from {source} by vrusim {__version__} (planner, sensor, V2X, time step: vrusim's defaults)\n"
    return head + body


def imported_scenario(source: Path, lenient: bool) -> Scenario:
    """The scenario of a `.xosc` file; its warnings (ignored elements) printed on stderr."""
    from vrusim.formats.xosc_import import import_xosc

    result = import_xosc(source, lenient)
    for warning in result.warnings:
        typer.echo(f"warning: {warning}", err=True)
    return result.scenario


def import_command(
    source: Annotated[
        Path,
        typer.Argument(metavar="FILE.xosc", help="OpenSCENARIO file (its .xodr road next to it).", show_default=False),
    ],
    out: Annotated[Path, file_option("--out", "SCENARIO.yaml", "The scenario YAML file to write.")],
    force: Annotated[bool, typer.Option("--force", help="Replace --out if it exists.")] = False,
    lenient: LenientOption = False,
    as_json: JsonOption = False,
) -> None:
    """Import an OpenSCENARIO file as a vrusim scenario YAML."""
    from vrusim.io.atomic import write_atomically

    with user_errors():
        check_output_file(out, "--out")
        check_not_input(out, source, "--out", "FILE.xosc")
        if out.exists() and not force:
            raise UserInputError(f"--out: {out} exists (--force replaces it)")
        scenario = imported_scenario(source, lenient)
        text = scenario_yaml_text(scenario, source.name)
        write_atomically(out, lambda path: path.write_text(text, encoding="utf-8"), "scenario YAML file")
    if as_json:
        print_json({"scenario": scenario.name, "file": str(out)})
        return
    console().print(f"Imported {escape(scenario.name)} from {escape(str(source))} into {escape(str(out))}.")
