"""Atomic file writes: write a temporary file in the target's folder, then rename it over the target.

A failure (a missing or read-only folder, a full disk, an exception in the writer) never leaves a
half-written target or a stray temporary file behind; an existing target stays as it was.
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Callable
from pathlib import Path

from vrusim.errors import UserInputError


def _default_file_mode() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return 0o666 & ~mask


def write_atomically(path: str | Path, write: Callable[[Path], None], what: str = "file") -> Path:
    """Run `write(temp)` on a temporary file next to `path`, then replace `path` with it; return `path`.

    An OSError (also from `write`) becomes a UserInputError naming the file; anything else propagates.
    """
    path = Path(path)
    if path.is_dir():
        raise UserInputError(f"{path}: cannot write {what}, it is a folder")
    try:
        handle, temp_name = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    except OSError as error:
        raise UserInputError(f"{path}: cannot write {what} ({error.strerror or error})") from None
    os.close(handle)
    temp = Path(temp_name)
    try:
        write(temp)
        os.chmod(temp, _default_file_mode())
        os.replace(temp, path)
    except OSError as error:
        temp.unlink(missing_ok=True)
        raise UserInputError(f"{path}: cannot write {what} ({error.strerror or error})") from None
    except BaseException:
        temp.unlink(missing_ok=True)
        raise
    return path


def write_together(targets: list[tuple[Path, Callable[[Path], None], str]]) -> list[Path]:
    """Write several files as one unit: every `write(temp)` runs on a temporary file next to its target, and
    only when all succeeded are they renamed over their targets; on any failure no target is touched and no
    temporary file is left. `targets` holds (path, write, what) triples."""
    temps: list[Path] = []
    try:
        for path, write, what in targets:
            if path.is_dir():
                raise UserInputError(f"{path}: cannot write {what}, it is a folder")
            try:
                handle, temp_name = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
                os.close(handle)
                temps.append(Path(temp_name))
                write(temps[-1])
                os.chmod(temps[-1], _default_file_mode())
            except OSError as error:
                raise UserInputError(f"{path}: cannot write {what} ({error.strerror or error})") from None
        for temp, (path, _, _) in zip(temps, targets, strict=True):
            os.replace(temp, path)
    finally:
        for temp in temps:
            temp.unlink(missing_ok=True)
    return [path for path, _, _ in targets]
