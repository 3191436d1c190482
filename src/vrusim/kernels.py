"""Compile batch kernels twice: serial for small batches, multi-threaded over variants for large ones.

A batch kernel loops over variants with `numba.prange`; variants never interact, so both versions give
bit-identical results. Threads only pay off for large batches (starting them costs ~10 µs per call), and
never when numba runs on one thread (a sweep worker process): then the serial version runs whatever the size.
Batch kernels write into arrays their caller allocates, so both versions compile without numba's reference
counting (`_nrt=False`), which would otherwise increment and decrement array counts inside the loops.
"""

from __future__ import annotations

import importlib.util
import os
import shutil
import stat
import sys
import tempfile
import time
import types
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numba
import platformdirs
from numba import prange

from vrusim import kernel_inlining
from vrusim.kernel_notices import attach as attach_compile_notices
from vrusim.kernel_notices import note_uncached
from vrusim.version import source_digest

__all__ = [
    "PARALLEL_MIN_BATCH",
    "BatchKernel",
    "batch_kernel",
    "kernel_cache_folder",
    "kernels_cached",
    "njit",
    "prange",
]

KERNEL_CACHE_UNUSED_DAYS = 7
"""A kernel cache folder of another source version that has not been used for this long is deleted, days."""


def kernel_cache_folder() -> Path | None:
    """Where numba keeps this source version's compiled kernels (`_configure_kernel_cache`); None when the user
    chose (NUMBA_CACHE_DIR), or when no folder could be written (every process then compiles the kernels it
    uses)."""
    return _cache_folder


def kernels_cached() -> bool:
    """Whether compiled kernels are kept in a cache folder (False: none could be written)."""
    return _caching


def _writable(folder: Path) -> bool:
    """Whether `folder` exists or can be made, and takes a file (numba's own test of a cache folder)."""
    try:
        folder.mkdir(parents=True, exist_ok=True)
        tempfile.TemporaryFile(dir=folder).close()
    except OSError:
        return False
    return True


def _private_temporary_folder() -> Path | None:
    """`<temporary folder>/vrusim-<user id>`, made if missing, if only this user can write it (cached kernels
    are pickled code: another user's files must never be loaded); None otherwise."""
    if not hasattr(os, "getuid"):
        return None
    folder = Path(tempfile.gettempdir()) / f"vrusim-{os.getuid()}"
    try:
        folder.mkdir(mode=0o700, exist_ok=True)
        status = folder.lstat()
    except OSError:
        return None
    private = stat.S_ISDIR(status.st_mode) and status.st_uid == os.getuid() and not status.st_mode & 0o022
    return folder if private else None


def _configure_kernel_cache() -> None:
    """Keep compiled kernels in a cache folder keyed by a hash of this package's source.

    Numba checks only a kernel's own file when reusing cached machine code; kernels inline helpers from other
    modules, so a change there could otherwise run stale code. A user-set NUMBA_CACHE_DIR is respected (and, if
    it cannot be written, kernels compile uncached, as below).
    Every source edit thus starts a new folder; folders of other versions unused for
    `KERNEL_CACHE_UNUSED_DAYS` are deleted (using a folder refreshes its time stamp). Runs once, when this module
    is first imported, before any kernel compiles; numba's own setting is changed, not the process environment,
    so child processes choose the same folder the same way.

    The folder is the user's cache folder (`platformdirs`), or, when that cannot be written (a read-only or
    missing home, as in some containers), the same under a private folder in the temporary folder. When neither
    can be written the kernels are compiled without caching (`njit` drops `cache=True`): numba's other places
    (the package's own `__pycache__`, its user-wide folder) are not keyed by the source hash, and without any it
    would refuse to compile.
    """
    global _cache_folder, _caching
    chosen = os.environ.get("NUMBA_CACHE_DIR")
    if chosen:
        if not _writable(Path(chosen)):
            _caching = False
            note_uncached()
        return
    digest = source_digest()[:16]
    folder = Path(platformdirs.user_cache_dir("vrusim", appauthor=False)) / "kernels" / digest
    if not _writable(folder):
        private = _private_temporary_folder()
        folder = private / "kernels" / digest if private is not None else None
        if folder is None or not _writable(folder):
            _caching = False
            note_uncached()
            return
    _cache_folder = folder
    numba.config.CACHE_DIR = str(folder)
    prune_kernel_caches(folder.parent, keep=folder.name)


_cache_folder: Path | None = None
"""This source version's kernel cache folder (`kernel_cache_folder`)."""
_caching = True
"""False when no cache folder could be written: kernels then compile without numba's cache."""


def njit(*args: Any, **options: Any) -> Any:
    """`numba.njit`, with `cache=True` dropped when no kernel cache folder could be written."""
    if not _caching:
        options.pop("cache", None)
    return numba.njit(*args, **options)


def prune_kernel_caches(root: Path, keep: str, unused_days: float = KERNEL_CACHE_UNUSED_DAYS) -> None:
    """Mark `root/keep` as used now; delete the other folders in `root` unused for `unused_days` (best effort)."""
    try:
        (root / keep).mkdir(parents=True, exist_ok=True)
        os.utime(root / keep)
        oldest = time.time() - unused_days * 86400.0
        for entry in root.iterdir():
            if entry.name != keep and entry.is_dir() and entry.stat().st_mtime < oldest:
                shutil.rmtree(entry, ignore_errors=True)
    except OSError:  # a read-only or shared cache: leave it as it is
        pass


def _load_numba_array_support_without_scipy() -> None:
    """Import numba's array implementations (`numba.np.arraymath`) without importing SciPy's linear algebra.

    Numba imports `numba.np.arraymath` before it compiles or loads its first kernel; at import that module
    checks for BLAS by importing `scipy.linalg` (about 0.2 s, most of it NumPy's f2py) to choose how `np.convolve`
    and `np.correlate` compute inner products. No vrusim kernel uses them, nor any BLAS routine; kernels that do
    still import SciPy when numba compiles them (numba's `ensure_blas`). So the check is skipped during the
    import and its answer set afterwards from whether SciPy is installed, which does not import it. Best effort:
    with a numba that differs, numba's own import happens instead.
    """
    if "numba.np.arraymath" in sys.modules:
        return
    try:
        from numba.np import linalg

        real_check = linalg.ensure_blas

        def skip_check() -> None:
            raise ImportError("BLAS check deferred by vrusim.kernels")

        linalg.ensure_blas = skip_check
        try:
            from numba.np import arraymath
        finally:
            linalg.ensure_blas = real_check
        arraymath.ensure_blas = real_check
        arraymath._HAVE_BLAS = importlib.util.find_spec("scipy") is not None
    except (ImportError, AttributeError):  # another numba: it checks as it always does
        pass


def _load_cached_kernels_without_refresh() -> None:
    """Load this package's cached kernels without first refreshing numba's compiler contexts.

    Before numba loads a kernel from its cache it refreshes the typing and target contexts: it imports and
    registers the implementations of everything numba can compile (about 0.15 s, once per process, paid by the
    first kernel a command uses). Loading machine code needs none of it, only numba's runtime (NRT), which is
    initialised here as numba does in the refresh; a kernel that compiles (a cache miss) still refreshes both
    contexts first, in numba's compiler. Only caches of kernels defined in this package take the short path;
    other libraries' keep numba's. Best effort: with a numba that differs, its own loading happens instead.
    """
    try:
        from numba.core.caching import Cache
        from numba.core.runtime.nrt import rtsys

        numba_load = Cache.load_overload
        guard = Cache._guard_against_spurious_io_errors
        Cache._load_overload  # noqa: B018 (numba's loader without the refresh: present, or keep numba's way)
    except (ImportError, AttributeError):
        return

    def load_overload(cache, sig, target_context):
        module = getattr(getattr(cache, "_py_func", None), "__module__", None) or ""
        if module.partition(".")[0] != __package__:
            return numba_load(cache, sig, target_context)
        rtsys.initialize(target_context)
        with guard(cache):
            return cache._load_overload(sig, target_context)
        return None  # the guard swallowed an I/O error: compile instead, as numba does

    Cache.load_overload = load_overload


_configure_kernel_cache()
_load_numba_array_support_without_scipy()
_load_cached_kernels_without_refresh()
kernel_inlining.install()  # a cold start compiles about twice as fast
attach_compile_notices()  # the command line's "compiling" notices, if it asked for them before numba loaded

PARALLEL_MIN_BATCH = 4096
"""Batches with at least this many variants run the multi-threaded version (if numba has several threads)."""


class BatchKernel:
    """A kernel whose first argument's leading axis (or `size=`) chooses serial or parallel execution.

    Each version's numba dispatcher is made when it is first used (making one costs about 0.3 ms; a command
    imports some 20 batch kernels and runs a few of them, most never in parallel). Batch kernels are called
    from Python only, never from other kernels, so nothing needs the dispatchers before then.
    """

    def __init__(self, function: Callable):
        self.function = function
        self._serial: Callable | None = None
        self._parallel: Callable | None = None
        self.__doc__ = function.__doc__

    @property
    def serial(self) -> Callable:
        """The serial version (numba dispatcher)."""
        if self._serial is None:
            self._serial = njit(cache=True, _nrt=False)(self.function)
        return self._serial

    @property
    def parallel(self) -> Callable:
        """The multi-threaded version (numba dispatcher)."""
        if self._parallel is None:
            # a renamed copy, so that the on-disk caches of the two versions do not collide
            self._parallel = njit(cache=True, parallel=True, _nrt=False)(_renamed(self.function, "_threaded"))
        return self._parallel

    def __call__(self, size: int, *args):
        if size >= PARALLEL_MIN_BATCH and numba.get_num_threads() > 1:
            return self.parallel(*args)
        return self.serial(*args)


def batch_kernel(function: Callable) -> BatchKernel:
    """Decorator: compile `function` (which loops over variants with `prange`, allocates nothing) as a
    `BatchKernel`."""
    return BatchKernel(function)


def _renamed(function: Callable, suffix: str) -> Callable:
    """A copy of `function` whose name (and so numba's cache file) carries `suffix`."""
    clone = types.FunctionType(
        function.__code__, function.__globals__, function.__name__ + suffix, function.__defaults__, function.__closure__
    )
    clone.__qualname__ = function.__qualname__ + suffix
    clone.__module__ = function.__module__
    return clone
