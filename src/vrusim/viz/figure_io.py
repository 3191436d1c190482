"""Checking and writing figure files: the suffix picks the format; writes are atomic."""

from __future__ import annotations

from pathlib import Path

from matplotlib.figure import Figure

from vrusim.errors import UserInputError
from vrusim.io.atomic import write_atomically
from vrusim.io.paths import check_output_file, shown
from vrusim.viz.literal_text import drawing

FIGURE_SUFFIXES = (".png", ".svg", ".pdf")
"""Figure file types, chosen by suffix."""


def check_output_path(path: str | Path, suffixes: tuple[str, ...], what: str) -> Path:
    """The path if a `what` can be written there: a known suffix and a usable name in an existing, writable folder
    (`vrusim.io.paths.check_output_file`); else a UserInputError saying why. Cheap, so commands call it before
    simulating."""
    path = Path(path)
    if path.suffix.lower() not in suffixes:
        found = path.suffix or "(no suffix)"
        raise UserInputError(f"{shown(path)}: unknown {what} type {found!r}; use {', '.join(suffixes)}")
    return check_output_file(path, what)


def check_figure_path(path: str | Path) -> Path:
    """`check_output_path` for a figure (.png, .svg or .pdf)."""
    return check_output_path(path, FIGURE_SUFFIXES, "figure")


def write_figure(fig: Figure, path: str | Path, dpi: float = 100.0) -> Path:
    """Save `fig` in the format of the suffix of `path`, atomically; return the path."""
    path = check_figure_path(path)
    fmt = path.suffix.lower().lstrip(".")
    with drawing(fig):
        return write_atomically(path, lambda temp: fig.savefig(temp, format=fmt, dpi=dpi), "figure")
