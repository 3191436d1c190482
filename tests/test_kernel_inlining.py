"""vrusim.kernel_inlining: kernels compiled with the copy-free inliner are the same machine code as numba's own."""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap

# A kernel that inlines vrusim helpers, some with helpers of their own (ttc_local -> _slab, rotate -> rotated),
# and a helper of its own module, which keeps numba's inlining. It prints the kernel's assembly (without its
# `.file` directive), its results, and whether the patch was installed.
_COMPILE = textwrap.dedent(
    """
    import json, sys
    import numpy as np
    import vrusim.kernels  # installs the inliner patch for the first compile
    from vrusim import kernel_inlining
    if sys.argv[1] == "numba":
        kernel_inlining._installed = True  # as if already installed: numba's own inlining stays
    from numba import njit
    from numba.core.inline_closurecall import InlineWorker
    from vrusim.geometry.contact import clearance_local, to_local
    from vrusim.geometry.ttc import ttc_local
    from vrusim.sim.ego import rotate

    @njit(inline="always")
    def doubled(value):
        return 2.0 * value

    @njit
    def kernel(x, out):
        for b in range(x.shape[0]):
            hx, hy = rotate(1.0, 0.0, x[b] * 1e-3)
            lx, ly = to_local(0.0, 0.0, hx, hy, x[b], 1.0)
            clearance, _, _ = clearance_local(lx, ly, 2.25, 0.9, 0.5)
            out[b] = clearance + ttc_local(lx, ly, -10.0, -1.0, 2.25, 0.9, 0.5, np.inf) + doubled(hx)

    x = np.linspace(1.0, 30.0, 8)
    out = np.zeros(8)
    kernel(x, out)
    asm = kernel.inspect_asm(kernel.signatures[0])
    print(json.dumps({
        "patched": InlineWorker.inline_function.__module__ == "vrusim.kernel_inlining",
        "asm": [line for line in asm.splitlines() if ".file" not in line],
        "out": out.tolist(),
    }))
    """
)


def _compile(inliner: str) -> dict:
    done = subprocess.run(
        [sys.executable, "-c", _COMPILE, inliner], capture_output=True, text=True, timeout=600, check=True
    )
    return json.loads(done.stdout)


def test_copy_free_inlining_gives_numbas_machine_code():
    ours, numbas = _compile("vrusim"), _compile("numba")
    assert ours["patched"] and not numbas["patched"]
    assert len(ours["asm"]) > 200  # a real kernel, with every helper inlined
    assert ours["asm"] == numbas["asm"]
    assert ours["out"] == numbas["out"]
