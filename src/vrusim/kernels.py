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
import sys
import time
import types
from collections.abc import Callable
from pathlib import Path

import numba
import platformdirs
from numba import njit, prange

from vrusim import kernel_inlining
from vrusim.kernel_notices import attach as attach_compile_notices
from vrusim.version import source_digest

__all__ = ["PARALLEL_MIN_BATCH", "BatchKernel", "batch_kernel", "kernel_cache_folder", "njit", "prange"]

KERNEL_CACHE_UNUSED_DAYS = 7
"""A kernel cache folder of another source version that has not been used for this long is deleted, days."""


def kernel_cache_folder() -> Path | None:
    """Where numba keeps this source version's compiled kernels; None when the user chose (NUMBA_CACHE_DIR)."""
    if os.environ.get("NUMBA_CACHE_DIR"):
        return None
    return Path(platformdirs.user_cache_dir("vrusim", appauthor=False)) / "kernels" / source_digest()[:16]


def _configure_kernel_cache() -> None:
    """Keep compiled kernels in a cache folder keyed by a hash of this package's source.

    Numba checks only a kernel's own file when reusing cached machine code; kernels inline helpers from other
    modules, so a change there could otherwise run stale code. A user-set NUMBA_CACHE_DIR is respected.
    Every source edit thus starts a new folder; folders of other versions unused for
    `KERNEL_CACHE_UNUSED_DAYS` are deleted (using a folder refreshes its time stamp). Runs once, when this module
    is first imported, before any kernel compiles; numba's own setting is changed, not the process environment,
    so child processes choose the same folder the same way.
    """
    folder = kernel_cache_folder()
    if folder is None:
        return
    numba.config.CACHE_DIR = str(folder)
    prune_kernel_caches(folder.parent, keep=folder.name)


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
