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
