"""Shared pieces of the `vrusim` commands: user-error handling, console, JSON output, option enums."""

from __future__ import annotations

import json
import os
from collections.abc import Iterator
from contextlib import contextmanager
from enum import StrEnum
from typing import Annotated, Any

import typer
from rich.console import Console

from vrusim.errors import UserInputError

USER_ERROR_EXIT_CODE = 2
"""Exit code for bad user input (the same as for a bad command-line option)."""

OneSource = Annotated[
    str,
    typer.Argument(
        metavar="FILE.yaml|TEST-ID",
        help="Scenario YAML file, or one Euro NCAP catalogue test id (`vrusim list`), e.g. CPNA-25/20kph/day.",
        show_default=False,
    ),
]
"""The SOURCE argument of commands that take one scenario (`vrusim.sources.single_source`)."""


class V2XSwitch(StrEnum):
    """Values of --v2x."""

    on = "on"
    off = "off"


def report_user_error(error: UserInputError) -> None:
    """Print a user error as one plain message on stderr (no markup, no traceback)."""
    typer.echo(f"Error: {error}", err=True)


@contextmanager
def user_errors() -> Iterator[None]:
    """Turn a UserInputError raised inside the block into its message on stderr and exit code 2."""
    try:
        yield
    except UserInputError as error:
        report_user_error(error)
        raise typer.Exit(USER_ERROR_EXIT_CODE) from None


def console() -> Console:
    """A console on the current stdout; wide enough for the tables when not writing to a terminal."""
    console = Console(highlight=False)
    if not console.is_terminal and "COLUMNS" not in os.environ:
        console = Console(highlight=False, width=120)
    return console


def print_json(document: Any) -> None:
    """Exactly one JSON document on stdout (strict: NaN or infinity would be a bug and raise)."""
    typer.echo(json.dumps(document, indent=2, allow_nan=False))
