"""The options the `vrusim` commands share, each declared once, and how their values are read.

    SOURCE        one scenario: a YAML file, a bundled name (`paper:pedestrian`) or a catalogue test id
    --planner     repeatable, or a comma list: `--planner fsm --planner aeb` = `--planner fsm,aeb`
    --v2x         on | off (`compare` also takes channel profile names)
    --seed        the random numbers' key (sensor noise, V2X loss)
    --out DIR     a folder for commands that write several files; one that is not empty needs --force
    --force       overwrite in a non-empty --out
    --json        one JSON document on stdout and nothing else

A command whose help needs its own default text makes its option with the factory here (`planner_option`, ...),
so name, metavar and parsing stay the same everywhere.
"""

from __future__ import annotations

from enum import StrEnum
from pathlib import Path
from typing import Annotated, Any

import typer

from vrusim.errors import UserInputError

PLANNER_NAMES = "fsm, none, aeb, predictive, module:Class or an entry-point name"
MAX_SEED = 2**63 - 1

OneSource = Annotated[
    str,
    typer.Argument(
        metavar="FILE.yaml|NAME|TEST-ID",
        help="Scenario YAML file, a bundled scenario (`vrusim examples`, e.g. paper:pedestrian) or one Euro NCAP "
        "catalogue test id (`vrusim list`, e.g. CPNA-25/20kph/day).",
        show_default=False,
    ),
]
"""The SOURCE argument of commands that take one scenario (`vrusim.sources.scenario_of`)."""

JsonOption = Annotated[
    bool, typer.Option("--json", help="Print the result as one JSON document on stdout and nothing else.")
]


def file_option(name: str, metavar: str, help: str) -> Any:
    """An option naming one file (or folder) to write, e.g. `--trace OUT.csv|OUT.parquet`."""
    return typer.Option(name, metavar=metavar, help=help, show_default=False)


ReportOption = Annotated[Path | None, file_option("--report", "OUT.html", "Also write a self-contained HTML report.")]
ForceOption = Annotated[
    bool,
    typer.Option(
        "--force", help="Write into a non-empty --out: replace files of the same name (sweep: the previous sweep)."
    ),
]


class V2XSwitch(StrEnum):
    """Values of --v2x."""

    on = "on"
    off = "off"


def planner_option(default: str, several: bool = False) -> Any:
    """--planner NAME: repeatable, or a comma list (a command that runs one planner refuses several)."""
    what = (
        f"Planners to compare: {PLANNER_NAMES}. Repeatable, or a comma list" if several else f"Planner: {PLANNER_NAMES}"
    )
    return typer.Option("--planner", metavar="NAME", help=f"{what}. Default: {default}.", show_default=False)


def v2x_switch_option(help: str) -> Any:
    """--v2x on|off (case-insensitive)."""
    return typer.Option("--v2x", case_sensitive=False, help=help)


def _check_seed(value: int | None) -> int | None:
    if value is not None and not 0 <= value <= MAX_SEED:
        raise typer.BadParameter(f"expected a whole number from 0 to 2^63 − 1, got {value}")
    return value


def seed_option(help: str) -> Any:
    """--seed N, a whole number from 0 to 2^63 − 1."""
    return typer.Option("--seed", metavar="N", callback=_check_seed, help=help, show_default=False)


def out_dir_option(writes: str) -> Any:
    """--out DIR of a command that writes several files."""
    return typer.Option(
        "--out",
        metavar="DIR",
        help=f"Folder to write {writes} into (created if missing; one that is not empty needs --force).",
        show_default=False,
    )


def split_names(values: list[str] | str | None, option: str) -> list[str]:
    """The names given to a repeatable or comma-list option, in order, each once ([] when not given); a value
    that names nothing (" , ") is a user error naming `option`."""
    values = [values] if isinstance(values, str) else list(values or ())
    names = [name.strip() for value in values for name in value.split(",") if name.strip()]
    if values and not names:
        raise UserInputError(f"{option}: expected a comma-separated list of names")
    return list(dict.fromkeys(names))


def planner_names(values: list[str] | None, option: str = "--planner") -> list[str]:
    """The planners given to --planner, each checked (an unknown one is a user error naming `option`)."""
    from vrusim.api.settings import check_planner

    return [check_planner(name, option) for name in split_names(values, option)]


def one_planner(values: list[str] | None, command: str) -> str | None:
    """The one planner of a command that runs one (None when not given); several are a user error."""
    names = planner_names(values)
    if len(names) > 1:
        raise UserInputError(
            f"--planner: `vrusim {command}` runs one planner, got {len(names)} ({', '.join(names)}); "
            "compare several with `vrusim compare`"
        )
    return names[0] if names else None


def switch_value(switch: V2XSwitch | None) -> bool | None:
    """--v2x as a bool (None when not given)."""
    return None if switch is None else switch is V2XSwitch.on


def check_out_dir(folder: Path, force: bool, option: str = "--out") -> None:
    """Refuse, before anything runs, an --out that cannot be a folder to write into (`vrusim.io.paths`), or a
    folder that is not empty without --force."""
    from vrusim.io.paths import check_output_folder, shown

    check_output_folder(folder, option)
    if not force and folder.is_dir() and any(folder.iterdir()):
        raise UserInputError(
            f"{option}: {shown(folder)} is not empty; give --force to overwrite, or choose a new folder"
        )


def make_out_dir(folder: Path, option: str = "--out") -> list[Path]:
    """Create the --out folder (and its parents) if missing; return the folders created."""
    from vrusim.io.paths import make_folder

    return make_folder(folder, option)


LenientOption = Annotated[
    bool,
    typer.Option(
        "--lenient",
        help="OpenSCENARIO: unsupported elements that do not change the motion (weather, controllers) are warnings.",
    ),
]
