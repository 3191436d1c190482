"""Tell the user when kernels compile: on a cold start (no cached machine code for this source version) numba
compiles every kernel a command uses, which takes up to a minute; a warm start loads them and says nothing.

The command line asks for notices before anything imports numba (`compile_notices`); `vrusim.kernels`, the
module every kernel is compiled through, attaches the listener when it is imported (`attach`). This module
imports numba only once that has happened, so asking costs nothing for commands that never simulate.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager, suppress
from typing import Any, TextIO

__all__ = ["attach", "compile_notices", "note_uncached"]

_stream: TextIO | None = None
"""Where notices go while some `compile_notices` block is open; None: nowhere."""
_listener: Any = None
"""The numba listener registered for `_stream`, once numba is loaded."""
_uncached = False
"""True when kernels compile without a cache (`vrusim.kernels`: no writable cache folder)."""


class _Notices:
    """A line on `stream` when a kernel starts compiling (a cache miss), then one per kernel compiled.

    Numba raises a "numba:compile" event only when it compiles, not when it loads a kernel from its cache, so a
    warm run prints nothing. A kernel's helpers compile inside it (nested events): only the outer one counts.
    """

    def __init__(self, stream: TextIO):
        self.stream = stream
        self.depth = 0
        self.compiled = 0
        self.first_start = 0.0
        self.kernel_start = 0.0

    def _say(self, text: str) -> None:
        with suppress(OSError, ValueError):  # a closed or broken stream: compiling goes on silently
            print(f"vrusim: {text}", file=self.stream, flush=True)

    def on_start(self, event: Any) -> None:
        self.depth += 1
        if self.depth > 1:
            return
        self.kernel_start = time.perf_counter()
        if self.compiled == 0:
            self.first_start = self.kernel_start
            import numba

            folder = numba.config.CACHE_DIR or "numba's cache folders"
            if _uncached:
                self._say(
                    "compiling the simulation kernels, up to a minute: no cache folder could be written, so every "
                    "run compiles them (set NUMBA_CACHE_DIR to a writable folder to keep them)"
                )
            else:
                self._say(
                    "compiling the simulation kernels: the first run of this version takes up to a minute; later "
                    f"runs load them from {folder}"
                )

    def on_end(self, event: Any) -> None:
        self.depth -= 1
        if self.depth > 0:
            return
        self.compiled += 1
        data = event.data if isinstance(event.data, dict) else {}
        function = getattr(data.get("dispatcher"), "py_func", None)
        name = f"{function.__module__.removeprefix('vrusim.')}.{function.__name__}" if function else "a kernel"
        now = time.perf_counter()
        self._say(
            f"compiled kernel {self.compiled} ({name}) in {now - self.kernel_start:.1f} s, "
            f"{now - self.first_start:.0f} s so far"
        )


def note_uncached() -> None:
    """Say, in the notices, that kernels are not cached: every run compiles them."""
    global _uncached
    _uncached = True


def attach() -> None:
    """Register the numba listener if notices are asked for and it is not yet registered (loads numba)."""
    global _listener
    if _stream is None or _listener is not None:
        return
    from numba.core import event

    class Listener(_Notices, event.Listener):
        pass

    _listener = Listener(_stream)
    event.register("numba:compile", _listener)


def _detach() -> None:
    global _listener
    if _listener is not None:
        from numba.core import event

        event.unregister("numba:compile", _listener)
        _listener = None


@contextmanager
def compile_notices(stream: TextIO | None = None) -> Iterator[None]:
    """Within the block, say on `stream` (default: stderr, never stdout) when kernels compile: a first line when
    compiling starts, then one line per kernel with its time (the progress of a cold start). Kernels loaded from
    the cache print nothing. Blocks do not nest (an inner block ends the notices)."""
    global _stream
    _stream = sys.stderr if stream is None else stream
    try:
        if "numba" in sys.modules:  # else `vrusim.kernels` attaches when it loads numba
            attach()
        yield
    finally:
        _detach()
        _stream = None
