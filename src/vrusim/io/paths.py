"""Output paths: check up front that a file or folder can be written there, and turn the operating system's
refusals (a name too long or with a null byte, a missing or read-only folder, a full disk) into one user error
that names the option, the path (shortened) and the system's reason (docs/errors.md).

    check_name(path, culprit)           a name the OS can use (no null byte, not too long)
    check_output_file(path, option)     a file that can be written: usable name, not a folder or device,
                                        in an existing writable folder
    check_output_folder(path, option)   a folder that exists writable, or can be created
    cannot_write(path, what, error)     the user error (a WriteError) for an OSError raised while writing
    for_option(option)                  a WriteError raised in the block names `option`
    new_folder(path, option)            create a folder (and missing parents); removed again if the block fails
"""

from __future__ import annotations

import errno
import os
import stat
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from vrusim.errors import UserInputError

SHOWN_CHARS = 80
"""Paths longer than this are shortened in messages (their start and end kept)."""


def shown(path: str | Path) -> str:
    """`path` for a message: control characters (a null byte) escaped, at most SHOWN_CHARS characters."""
    text = str(path)
    if not text.isprintable():
        text = text.encode("unicode_escape").decode("ascii")
    if len(text) <= SHOWN_CHARS:
        return text
    half = (SHOWN_CHARS - 3) // 2
    return f"{text[:half]}...{text[-(SHOWN_CHARS - 3 - half) :]}"


def os_reason(error: BaseException) -> str:
    """The system's reason for `error`, in words ("File name too long", "a null byte in the name")."""
    if isinstance(error, ValueError) and "null" in str(error):
        return "a null byte in the name"
    return getattr(error, "strerror", None) or str(error)


class WriteError(UserInputError):
    """A file could not be written (the system's refusal as a user error); `for_option` names the option."""


def cannot_write(path: str | Path, what: str, error: BaseException) -> WriteError:
    """The user error for `error` (an OSError or a null-byte ValueError) raised while writing `what` to `path`."""
    return WriteError(f"{shown(path)}: cannot write {what} ({os_reason(error)})")


@contextmanager
def for_option(option: str) -> Iterator[None]:
    """Name `option` in front of the message of a WriteError raised inside the block (other errors pass)."""
    try:
        yield
    except WriteError as error:
        raise UserInputError(f"{option}: {error}") from None


def check_name(path: str | Path, culprit: str) -> Path:
    """`path` as a Path if the OS can use it as a name; a UserInputError naming `culprit` if it holds a null byte
    or is too long (a part over NAME_MAX or the whole over PATH_MAX)."""
    try:
        os.lstat(path)
    except ValueError as error:
        raise UserInputError(f"{culprit}: cannot use {shown(path)} as a file name ({os_reason(error)})") from None
    except OSError as error:
        if error.errno == errno.ENAMETOOLONG:
            raise UserInputError(f"{culprit}: cannot use {shown(path)} as a file name ({os_reason(error)})") from None
    return Path(path)


def _mode(path: Path) -> int | None:
    """The st_mode of `path` (symlinks followed), None when it does not exist."""
    try:
        return os.stat(path).st_mode
    except (FileNotFoundError, NotADirectoryError):
        return None


def _check_writable_folder(folder: Path, option: str) -> None:
    """A UserInputError naming `option` unless `folder` is an existing folder this process may write into."""
    try:
        mode = _mode(folder)
    except OSError as error:
        raise UserInputError(f"{option}: cannot use folder {shown(folder)} ({os_reason(error)})") from None
    if mode is None:
        raise UserInputError(f"{option}: folder {shown(folder)} does not exist")
    if not stat.S_ISDIR(mode):
        raise UserInputError(f"{option}: folder {shown(folder)} does not exist (it is a file)")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise UserInputError(f"{option}: folder {shown(folder)} is not writable (permission denied)")


def check_output_file(path: str | Path, option: str) -> Path:
    """`path` as a Path if a file can be written there: a usable name, not a folder or a special file (a device,
    a FIFO), in an existing folder this process may write into; else a UserInputError naming `option`."""
    path = check_name(path, option)
    try:
        mode = _mode(path)
    except OSError as error:
        raise UserInputError(f"{option}: cannot use {shown(path)} ({os_reason(error)})") from None
    if mode is not None and stat.S_ISDIR(mode):
        raise UserInputError(f"{option}: {shown(path)} is a folder")
    if mode is not None and not stat.S_ISREG(mode):
        raise UserInputError(f"{option}: {shown(path)} is not a regular file")
    _check_writable_folder(path.parent, option)
    return path


def same_file(a: str | Path, b: str | Path) -> bool:
    """Whether `a` and `b` name one file: the same resolved path (symlinks followed), or one file under two names
    (a hard link)."""
    try:
        return Path(a).resolve() == Path(b).resolve() or os.path.samefile(a, b)
    except (OSError, RuntimeError, ValueError):  # one does not exist, a symlink loop, a null byte
        return False


def check_not_input(path: Path, source: Path, option: str, what: str) -> None:
    """A UserInputError naming `option` if the output `path` is the input file `source` (`what`, e.g. FILE.xosc),
    which writing would replace."""
    if same_file(path, source):
        raise UserInputError(f"{option}: {shown(path)} is the {what} being read; writing it would replace it")


def _nearest_existing(path: Path) -> Path:
    """`path` or its closest ancestor that exists (as anything)."""
    for candidate in (path, *path.parents):
        if os.path.lexists(candidate):
            return candidate
    return Path(path.anchor or ".")  # pragma: no cover (the root or the working folder always exists)


def check_output_folder(path: str | Path, option: str) -> Path:
    """`path` as a Path if files can be written into it: an existing writable folder, or a missing one whose
    closest existing ancestor is a writable folder (it can be created); else a UserInputError naming `option`."""
    path = check_name(path, option)
    try:
        mode = _mode(path)
    except OSError as error:
        raise UserInputError(f"{option}: cannot use {shown(path)} ({os_reason(error)})") from None
    if mode is not None and not stat.S_ISDIR(mode):
        raise UserInputError(f"{option}: {shown(path)} exists and is not a folder")
    ancestor = path if mode is not None else _nearest_existing(path.parent)
    if not ancestor.is_dir():
        raise UserInputError(f"{option}: cannot create {shown(path)} ({shown(ancestor)} is not a folder)")
    if not os.access(ancestor, os.W_OK | os.X_OK):
        raise UserInputError(f"{option}: folder {shown(ancestor)} is not writable (permission denied)")
    return path


def make_folder(path: Path, option: str) -> list[Path]:
    """Create `path` and its missing parents; return the folders created, outermost first. A failure removes
    them again and is a UserInputError naming `option`."""
    created: list[Path] = []
    try:
        for folder in (*reversed(path.parents), path):
            if not folder.is_dir():
                folder.mkdir()
                created.append(folder)
    except FileExistsError:  # a file (or a dangling link) where a folder should be
        remove_folders(created)
        raise UserInputError(f"{option}: cannot create {shown(path)} ({shown(folder)} is not a folder)") from None
    except (OSError, ValueError) as error:
        remove_folders(created)
        raise UserInputError(f"{option}: cannot create {shown(path)} ({os_reason(error)})") from None
    return created


def remove_folders(created: list[Path]) -> None:
    """Remove the folders `make_folder` created, innermost first, each only if empty (files are never deleted)."""
    for folder in reversed(created):
        try:
            folder.rmdir()
        except FileNotFoundError:  # removed already
            continue
        except OSError:  # not empty: it holds files of someone else, keep it (and so its parents)
            return


@contextmanager
def new_folder(path: Path, option: str) -> Iterator[list[Path]]:
    """Create the folder `path` (and missing parents) for the block; if the block raises, the folders created
    here are removed again when empty. Yields the folders created."""
    created = make_folder(path, option)
    try:
        yield created
    except BaseException:
        remove_folders(created)
        raise
