"""Atomic file writes: write a temporary file in the target's folder, then rename it over the target.

A failure (a missing or read-only folder, a full disk, an exception in the writer) never leaves a
half-written target or a stray temporary file behind; an existing target stays as it was. Every OSError
becomes one UserInputError naming the file (shortened) and the system's reason (`vrusim.io.paths`).
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Callable
from pathlib import Path

from vrusim.io.paths import WriteError, cannot_write, shown

TEMP_NAME_CHARS = 64
"""At most this many characters of the target's name go into its temporary file's name (which must fit too)."""


def _default_file_mode() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return 0o666 & ~mask


def _temporary(path: Path, what: str) -> Path:
    """A new empty temporary file next to `path` (`.NAME.XXXX.tmp`); a folder at `path` is a user error."""
    if path.is_dir():
        raise WriteError(f"{shown(path)}: cannot write {what}, it is a folder")
    handle, temp_name = tempfile.mkstemp(prefix=f".{path.name[:TEMP_NAME_CHARS]}.", suffix=".tmp", dir=path.parent)
    os.close(handle)
    return Path(temp_name)


def run_writer(write: Callable[[Path], None], temp: Path) -> None:
    """Run one writer on its temporary file (the one place file contents are written; tests replace it to
    simulate a full disk)."""
    write(temp)


def write_atomically(path: str | Path, write: Callable[[Path], None], what: str = "file") -> Path:
    """Run `write(temp)` on a temporary file next to `path`, then replace `path` with it; return `path`.

    An OSError (also from `write`) becomes a UserInputError naming the file; anything else propagates.
    """
    return write_together([(Path(path), write, what)])[0]


def write_together(targets: list[tuple[Path, Callable[[Path], None], str]]) -> list[Path]:
    """Write several files as one unit: every `write(temp)` runs on a temporary file next to its target, and
    only when all succeeded are they renamed over their targets; on any failure no target is touched and no
    temporary file is left. `targets` holds (path, write, what) triples."""
    temps: list[Path] = []
    try:
        for path, write, what in targets:
            try:
                temps.append(_temporary(path, what))
            except (OSError, ValueError) as error:  # ValueError: a null byte in the name
                raise cannot_write(path, what, error) from None
            try:
                run_writer(write, temps[-1])
                os.chmod(temps[-1], _default_file_mode())
            except OSError as error:
                raise cannot_write(path, what, error) from None
        for temp, (path, _, what) in zip(temps, targets, strict=True):
            try:
                os.replace(temp, path)
            except OSError as error:
                raise cannot_write(path, what, error) from None
    finally:
        for temp in temps:
            temp.unlink(missing_ok=True)
    return [path for path, _, _ in targets]
