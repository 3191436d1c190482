"""Compile batch kernels twice: serial for small batches, multi-threaded over variants for large ones.

A batch kernel loops over variants with `numba.prange`; variants never interact, so both versions give
bit-identical results. Threads only pay off for large batches (starting them costs ~10 µs per call).
"""

from __future__ import annotations

from collections.abc import Callable

from numba import njit

PARALLEL_MIN_BATCH = 4096
"""Batches with at least this many variants run the multi-threaded version."""


class BatchKernel:
    """A kernel whose first argument's leading axis (or `size=`) chooses serial or parallel execution."""

    def __init__(self, function: Callable):
        self.serial = njit(cache=True)(function)
        self.parallel = njit(cache=True, parallel=True)(function)
        self.__doc__ = function.__doc__

    def __call__(self, size: int, *args):
        kernel = self.parallel if size >= PARALLEL_MIN_BATCH else self.serial
        return kernel(*args)


def batch_kernel(function: Callable) -> BatchKernel:
    """Decorator: compile `function` (which loops over variants with `prange`) as a `BatchKernel`."""
    return BatchKernel(function)
