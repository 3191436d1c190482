"""Checking and writing figure files: the suffix picks the format; writes are atomic."""

from __future__ import annotations

import os
from pathlib import Path

from matplotlib.figure import Figure

from vrusim.errors import UserInputError
from vrusim.io.atomic import write_atomically

FIGURE_SUFFIXES = (".png", ".svg", ".pdf")
"""Figure file types, chosen by suffix."""


def check_output_path(path: str | Path, suffixes: tuple[str, ...], what: str) -> Path:
    """The path if a `what` can be written there: a known suffix and an existing, writable folder; else a
    UserInputError saying why. Cheap, so commands call it before simulating."""
    path = Path(path)
    if path.suffix.lower() not in suffixes:
        found = path.suffix or "(no suffix)"
        raise UserInputError(f"{path}: unknown {what} type {found!r}; use {', '.join(suffixes)}")
    if path.is_dir():
        raise UserInputError(f"{path}: is a folder")
    try:
        check_folder(path.parent)
    except UserInputError as error:
        raise UserInputError(f"{path}: {error}") from None
    return path


def check_folder(folder: Path) -> None:
    """A UserInputError unless `folder` exists, is a folder and is writable."""
    if not folder.is_dir():
        raise UserInputError(f"folder {folder} does not exist")
    if not os.access(folder, os.W_OK):
        raise UserInputError(f"folder {folder} is not writable")


def check_figure_path(path: str | Path) -> Path:
    """`check_output_path` for a figure (.png, .svg or .pdf)."""
    return check_output_path(path, FIGURE_SUFFIXES, "figure")


def write_figure(fig: Figure, path: str | Path, dpi: float = 100.0) -> Path:
    """Save `fig` in the format of the suffix of `path`, atomically; return the path."""
    path = check_figure_path(path)
    fmt = path.suffix.lower().lstrip(".")
    return write_atomically(path, lambda temp: fig.savefig(temp, format=fmt, dpi=dpi), "figure")
