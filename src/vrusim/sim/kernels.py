"""Compile batch kernels twice: serial for small batches, multi-threaded over variants for large ones.

A batch kernel loops over variants with `numba.prange`; variants never interact, so both versions give
bit-identical results. Threads only pay off for large batches (starting them costs ~10 µs per call), and
never when numba runs on one thread (a sweep worker process): then the serial version runs whatever the size.
Batch kernels write into arrays their caller allocates, so both versions compile without numba's reference
counting (`_nrt=False`), which would otherwise increment and decrement array counts inside the loops.
"""

from __future__ import annotations

import types
from collections.abc import Callable

import numba
from numba import njit

PARALLEL_MIN_BATCH = 4096
"""Batches with at least this many variants run the multi-threaded version (if numba has several threads)."""


class BatchKernel:
    """A kernel whose first argument's leading axis (or `size=`) chooses serial or parallel execution."""

    def __init__(self, function: Callable):
        self.serial = njit(cache=True, _nrt=False)(function)
        # a renamed copy, so that the on-disk caches of the two versions do not collide
        self.parallel = njit(cache=True, parallel=True, _nrt=False)(_renamed(function, "_threaded"))
        self.__doc__ = function.__doc__

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
