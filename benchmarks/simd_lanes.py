"""What SIMD across variants is worth: the engine's contact geometry (clearance and TTC of a rectangle and a circle)
run variant after variant, as the compiled step runs, and with the variants as the innermost loop, which LLVM
can vectorise (several variants in one vector register).

Run: python benchmarks/simd_lanes.py [--batch 2000] [--steps 1000] [--repeats 5] [--json]

The workload: B egos (the paper pedestrian case's rectangle, cruise speeds of the engine benchmark) drive along x
while a pedestrian (radius 0.5 m) crosses at 1.5 m/s; each step moves both, then computes vrusim's own
`geometry.contact.clearance_local` and `geometry.ttc.ttc_local` (the functions the engine's step calls) and keeps
each variant's minimum clearance and TTC. Both loop orders do the same arithmetic per variant and step, so their
results are bit-identical (checked in each run and by tests/test_benchmarks.py). The table gives the time of
each order and how many packed double-precision instructions (ymm / zmm registers) its machine code holds: 0
means LLVM did not vectorise it.

This is the part of the step most open to vectorising: no route look-ups (gathers), no Newton iterations or
queue scans (loops whose length differs from variant to variant). Its gain is therefore a generous estimate of
what restructuring the whole step into vector lanes could give.
"""

from __future__ import annotations

import math
import sys
import time
from pathlib import Path

import numpy as np
from numba import njit

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_engine import speeds
from machine import run_kernel_benchmark
from vrusim.geometry.contact import clearance_local, to_local
from vrusim.geometry.ttc import ttc_local

HALF_LENGTH_M, HALF_WIDTH_M, RADIUS_M = 2.25, 0.9, 0.5
EGO_Y_M, PED_X_M, PED_SPEED_MPS, DT_S = -1.75, 18.0, 1.5, 0.01


@njit(cache=True, inline="always")
def _contact_step(x, py, speed):  # pragma: no cover (compiled)
    """Move the ego (centre x, m) and the pedestrian (y, m) one step; their clearance (m) and TTC (s) after it."""
    x += speed * DT_S
    py += PED_SPEED_MPS * DT_S
    lx, ly = to_local(x, EGO_Y_M, 1.0, 0.0, PED_X_M, py)
    clearance = clearance_local(lx, ly, HALF_LENGTH_M, HALF_WIDTH_M, RADIUS_M)[0]
    wx, wy = to_local(speed, 0.0, 1.0, 0.0, 0.0, PED_SPEED_MPS)
    ttc = ttc_local(lx, ly, wx, wy, HALF_LENGTH_M, HALF_WIDTH_M, RADIUS_M, np.inf)
    return x, py, clearance, ttc


@njit(cache=False)  # compiled in each run: numba gives no machine code of a cached kernel
def per_variant(x, py, speed, min_clearance, min_ttc, n_steps):  # pragma: no cover (compiled)
    """Each variant's whole horizon in turn (the compiled step's order)."""
    for b in range(x.shape[0]):
        for _ in range(n_steps):
            x[b], py[b], clearance, ttc = _contact_step(x[b], py[b], speed[b])
            min_clearance[b] = min(min_clearance[b], clearance)
            min_ttc[b] = min(min_ttc[b], ttc)


@njit(cache=False)
def across_variants(x, py, speed, min_clearance, min_ttc, n_steps):  # pragma: no cover (compiled)
    """Every variant's step in turn, step after step (the variants innermost: vectorisable)."""
    for _ in range(n_steps):
        for b in range(x.shape[0]):
            x[b], py[b], clearance, ttc = _contact_step(x[b], py[b], speed[b])
            min_clearance[b] = min(min_clearance[b], clearance)
            min_ttc[b] = min(min_ttc[b], ttc)


ORDERS = {"per variant": per_variant, "across variants": across_variants}


def _state(batch: int) -> list[np.ndarray]:
    """Start state: ego centres 50 m before the crossing, pedestrians 10 m to its side, minima at inf."""
    return [np.full(batch, -50.0), np.full(batch, -10.0), np.ascontiguousarray(speeds(batch))] + [
        np.full(batch, np.inf) for _ in range(2)
    ]


def packed_instructions(kernel) -> int:
    """Packed double-precision instructions (ymm / zmm operands) in the kernel's machine code."""
    assembly = "\n".join(kernel.inspect_asm().values())
    return sum(1 for line in assembly.splitlines() if "pd\t" in line and ("ymm" in line or "zmm" in line))


def measure(batch: int, n_steps: int, repeats: int) -> list[dict]:
    """Best wall time of each loop order; rows with ns a variant-step, speed-up and bit-identity."""
    rows, first = [], None
    for order, kernel in ORDERS.items():
        kernel(*_state(2), 2)  # compile
        best = math.inf
        for _ in range(repeats):
            state = _state(batch)
            started = time.perf_counter()
            kernel(*state, n_steps)
            best = min(best, time.perf_counter() - started)
        first = first or (best, state)
        rows.append(
            {
                "order": order,
                "seconds": best,
                "ns_per_variant_step": best / (batch * n_steps) * 1e9,
                "speed_up": first[0] / best,
                "packed_instructions": packed_instructions(kernel),
                "identical": all(np.array_equal(a, b) for a, b in zip(state, first[1], strict=True)),
            }
        )
    return rows


COLUMNS = {
    "loop order": lambda r: r["order"],
    "wall s": lambda r: f"{r['seconds']:.4f}",
    "ns a variant-step": lambda r: f"{r['ns_per_variant_step']:.2f}",
    "speed-up": lambda r: f"{r['speed_up']:.2f}×",
    "packed instructions": lambda r: str(r["packed_instructions"]),
    "identical results": lambda r: "yes" if r["identical"] else "NO",
}
"""The table's headings and each one's cell of a row of `measure`."""


if __name__ == "__main__":
    run_kernel_benchmark(__doc__.splitlines()[0], measure, "Contact geometry in two loop orders", COLUMNS)
