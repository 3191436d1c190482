"""Compile vrusim's kernels about twice as fast on a cold start, by inlining without numba's needless IR copies.

vrusim's per-variant functions are `inline="always"`: numba inlines them into the kernels at the level of its own
IR (the compiled step of a built-in planner inlines about 150 calls, nested four or five deep). For every call
numba's `InlineWorker.inline_function` builds the callee's IR afresh (`run_untyped_passes`) and hands it to
`inline_ir`, which deep-copies it twice, block by block: once to have a copy to mutate, once to return an
unmutated original. Each block's copy also copies the function's whole scope (every variable), so the cost grows
with blocks × variables at every level of nesting: about 60 % of compiling `_run_none` was `copy.deepcopy`.
Both copies are needless on this path: nothing else holds the fresh IR, and numba's only caller of
`inline_function`, the `InlineInlinables` pass, drops the returned original (numba/numba#8989; numba-cuda#688).

`install` patches `inline_function`, for callees defined in this package only, to let `inline_ir`'s copies
be the IR itself. The machine code is the same: `tests/test_kernel_inlining.py` compiles a kernel with nested
inlined helpers both ways, in fresh processes, and compares its disassembly. The patch is installed when numba
first starts compiling in a process (a numba event), so a warm start, which only loads cached kernels, never
imports numba's inliner. Best effort: with a numba whose inliner differs, its own inlining runs.
"""

from __future__ import annotations

import copy
from typing import Any

__all__ = ["install"]

_installed = False


class _NoDeepCopies:
    """The `copy` module as numba's inliner sees it while it inlines fresh IR: `deepcopy` returns its argument,
    everything else is the module's own."""

    @staticmethod
    def deepcopy(value: Any, memo: Any = None) -> Any:
        return value

    def __getattr__(self, name: str) -> Any:
        return getattr(copy, name)


def _patch_inliner() -> None:
    """Replace `InlineWorker.inline_function` by the copy-free version for this package's callees (once)."""
    global _installed
    if _installed:
        return
    _installed = True
    try:
        from numba.core import inline_closurecall

        worker = inline_closurecall.InlineWorker
        numba_inline_function = worker.inline_function
        worker.run_untyped_passes  # noqa: B018 (the parts the patch calls: present, or keep numba's way)
        worker.inline_ir  # noqa: B018
    except (ImportError, AttributeError):
        return
    if inline_closurecall.copy is not copy:  # the inliner no longer copies through the module: leave it alone
        return
    package = __package__ or "vrusim"
    no_copies = _NoDeepCopies()

    def inline_function(self: Any, caller_ir: Any, block: Any, i: int, function: Any, arg_typs: Any = None) -> Any:
        if (getattr(function, "__module__", None) or "").partition(".")[0] != package:
            return numba_inline_function(self, caller_ir, block, i, function, arg_typs)
        callee_ir = self.run_untyped_passes(function)  # fresh: nothing else holds it
        inline_closurecall.copy = no_copies  # numba compiles under its global lock: no other thread is inlining
        try:  # the "unmutated original" it returns is then the inlined IR: InlineInlinables drops it
            return self.inline_ir(caller_ir, block, i, callee_ir, function.__code__.co_freevars, arg_typs=arg_typs)
        finally:
            inline_closurecall.copy = copy

    worker.inline_function = inline_function


def install() -> None:
    """Patch numba's inliner when numba first starts compiling in this process (needs numba loaded)."""
    if _installed:
        return
    from numba.core import event

    class FirstCompile(event.Listener):
        def on_start(self, event_: Any) -> None:
            _patch_inliner()

        def on_end(self, event_: Any) -> None:
            pass

    event.register("numba:compile", FirstCompile())
