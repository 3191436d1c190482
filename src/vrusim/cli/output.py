"""How the `vrusim` commands talk back: user errors on stderr with exit code 2, the console, JSON on stdout."""

from __future__ import annotations

import json
import os
import re
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

import typer
from rich.console import Console
from rich.markup import escape as escape_markup

from vrusim.cli.fit import fitted
from vrusim.errors import UserInputError

USER_ERROR_EXIT_CODE = 2
"""Exit code for bad user input (the same as for a bad command-line option)."""
WIDTH_WITHOUT_TERMINAL = 120
"""Console width when stdout is not a terminal and COLUMNS is not set (a pipe, a file)."""


_CONTROL = re.compile(r"[\x00-\x08\x0b-\x1f\x7f-\x9f]")
"""Control characters other than newline and tab (ESC starts a terminal escape sequence)."""


def visible(text: str) -> str:
    """`text` with its control characters written as escapes (`\\x1b`), so none reaches the terminal raw."""
    return _CONTROL.sub(lambda match: match.group().encode("unicode_escape").decode("ascii"), text)


def escape(text: object) -> str:
    """User text (a name, a path, a value) for a console line with markup: shown literally, control characters
    as escapes."""
    return escape_markup(visible(str(text)))


def report_user_error(error: UserInputError) -> None:
    """Print a user error as one plain message on stderr (no markup, no traceback, no raw control characters)."""
    typer.echo(visible(f"Error: {error}"), err=True)


def warn(message: str) -> None:
    """Print a warning on stderr (stdout stays clean for JSON)."""
    typer.echo(visible(f"Warning: {message}"), err=True)


@contextmanager
def user_errors() -> Iterator[None]:
    """Turn a UserInputError raised inside the block into its message on stderr and exit code 2."""
    try:
        yield
    except UserInputError as error:
        report_user_error(error)
        raise typer.Exit(USER_ERROR_EXIT_CODE) from None


@contextmanager
def named_errors(option: str) -> Iterator[None]:
    """Prefix the message of a UserInputError raised inside the block with `option` (the culprit)."""
    try:
        yield
    except UserInputError as error:
        raise UserInputError(f"{option}: {error}") from None


class FittingConsole(Console):
    """A console whose tables fit its width by wrapping at spaces (`vrusim.cli.fit`), and whose text lines never
    pass a control character to the terminal raw (`visible`; markup in user text needs `escape`)."""

    def print(self, *objects: Any, **kwargs: Any) -> None:
        objects = tuple(visible(item) if isinstance(item, str) else item for item in objects)
        super().print(*(fitted(item, self) for item in objects), **kwargs)


def console() -> Console:
    """A console on the current stdout, as wide as the terminal or COLUMNS; 120 columns into a pipe or file."""
    console = FittingConsole(highlight=False)
    if not console.is_terminal and "COLUMNS" not in os.environ:
        console = FittingConsole(highlight=False, width=WIDTH_WITHOUT_TERMINAL)
    return console


def print_json(document: Any) -> None:
    """Exactly one JSON document on stdout (strict: NaN or infinity would be a bug and raise)."""
    typer.echo(json.dumps(document, indent=2, allow_nan=False))
