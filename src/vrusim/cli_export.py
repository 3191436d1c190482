"""`vrusim export SOURCE --format openscenario|commonroad --out DIR`: scenarios as files for other tools.

SOURCE is a scenario YAML file, a catalogue test id (`CPNA-25/20kph/day`), a catalogue code or prefix
(`CPNA-25`, `CPNA`: its day tests, plus night with --night) or `all` (the whole catalogue).
"""

from __future__ import annotations

import difflib
from enum import StrEnum
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer
from rich.markup import escape

from vrusim.cli_support import console, user_errors
from vrusim.errors import UserInputError

if TYPE_CHECKING:
    from vrusim.scenario.schema import Scenario

YAML_SUFFIXES = (".yaml", ".yml")
LISTED_FILES = 6
"""Written files are listed one per line up to this many; more are summarised."""


class ExportFormat(StrEnum):
    """Values of --format."""

    openscenario = "openscenario"
    commonroad = "commonroad"


def _catalogue_ids(night: bool) -> list[str]:
    from vrusim.catalog.ncap import select

    return [test.test_id for test in select(night=night)]


def catalogue_scenarios(source: str, night: bool) -> list[Scenario]:
    """The catalogue tests SOURCE names (a test id, a code or prefix, or `all`) as Scenarios."""
    from vrusim.catalog.ncap import select
    from vrusim.catalog.ncap_build import build_test

    wanted = source.strip()
    if wanted.lower() == "all":
        tests = select(night=night)
    elif "/" in wanted:
        tests = [t for t in select([wanted.split("/")[0]], night=True) if t.test_id.lower() == wanted.lower()]
    else:
        tests = select([wanted], night=night)
    if not tests:
        raise UserInputError(f"SOURCE: {source!r} selects no catalogue test")
    return [build_test(test).scenario for test in tests]


def resolve_source(source: str, night: bool) -> list[Scenario]:
    """The scenarios SOURCE names: one YAML file, or catalogue tests; an unknown name suggests close ids."""
    from vrusim.scenario.loading import load_scenario

    path = Path(source)
    if path.suffix.lower() in YAML_SUFFIXES or path.exists():
        if path.is_dir():
            raise UserInputError(f"SOURCE: {source} is a folder, expected a scenario YAML file or a catalogue id")
        return [load_scenario(path)]
    try:
        return catalogue_scenarios(source, night)
    except UserInputError:
        ids = _catalogue_ids(night=True)
        codes = sorted({test_id.split("/")[0] for test_id in ids})
        close = difflib.get_close_matches(source, [*codes, *ids], n=5, cutoff=0.5)
        hint = f"; did you mean {', '.join(close)}?" if close else f"; catalogue codes: {', '.join(codes)}"
        raise UserInputError(
            f"SOURCE: {source!r} is neither a scenario file nor a catalogue test id, code or 'all'{hint}"
        ) from None


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
