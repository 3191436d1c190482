"""What the fused reference's layout is worth: the kernel of `fused_reference.py` with its data laid out as
vrusim's engine lays it out, the arithmetic unchanged.

Run: python benchmarks/reference_layouts.py [--batch 2000] [--steps 1000] [--repeats 5] [--json]

The reference keeps every setting of the paper pedestrian case as a compile-time constant and each variant's state
in local variables for its whole horizon. vrusim's engine reads each variant's settings from arrays (a sweep varies
any of them) and keeps the state in arrays between the parts of a step. The variants, made from the reference's own
source by substitution so that the arithmetic stays the same, are:

- `constants`: the reference as it is;
- `settings`: its 31 settings read from a per-variant table, `S[b, i]`, wherever the reference uses them;
- `record`: that, and its 13 state variables loaded from a per-variant row at the start of every step and stored
  back at its end;
- `arrays`: the settings and the state as 31 + 13 separate one-dimensional arrays, vrusim's layout.

All four give bit-identical results (checked in each run and by tests/test_benchmarks.py). The ratio of a variant's
time to the reference's bounds what a change of layout alone could gain the engine.
"""

from __future__ import annotations

import importlib.util
import math
import re
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import fused_reference
from bench_engine import speeds
from machine import run_kernel_benchmark

SETTINGS = (
    "EGO_HALF_LENGTH_M", "EGO_HALF_WIDTH_M", "REAR_TO_CENTRE_M", "EGO_Y_M", "EGO_START_X_M", "MAX_ACCEL",
    "MAX_DECEL", "LAG_S", "MAX_JERK", "K_LATERAL", "K_HEADING", "PED_X_M", "PED_Y_M", "PED_TOP_MPS",
    "PED_ACCEL_MPS2", "PED_RADIUS_M", "PED_TRIGGER_S", "SENSOR_RANGE_M", "COS_HALF_FOV", "RSU_X_M", "RSU_Y_M",
    "COMM_RANGE_M", "COVERAGE_M", "HEADWAY_S", "PRE_SLOW", "EMERGENCY", "CRUISE_ACCEL", "CRUISE_GAIN",
    "MARGIN_M", "TIME_MARGIN_S", "ARRIVAL_MIN_MPS",
)  # fmt: skip
"""The reference's settings, in the order of the table's columns (COS_HALF_FOV: the cosine of its half field of
view, which the reference computes from SENSOR_HALF_FOV_RAD)."""
STATE = ("x", "y", "hx", "hy", "v", "act", "mode", "py", "pv", "started", "clear_min", "ttc_min", "first")
"""The reference's per-variant state variables, in the order of the record's columns."""
LAYOUTS = ("constants", "settings", "record", "arrays")


def _kernel_source() -> tuple[str, str]:
    """(the module text before the kernels, the two kernels' text) of fused_reference.py."""
    source = Path(fused_reference.__file__).read_text(encoding="utf-8")
    start = source.index('@njit(cache=True, inline="always")\ndef time_to_cover')
    end = source.index("def run_reference")
    prelude = source[:start].replace("from bench_engine import packed_batch, shortened", "")
    prelude += "COS_HALF_FOV = math.cos(SENSOR_HALF_FOV_RAD)\n"
    kernels = source[start:end].replace("math.cos(SENSOR_HALF_FOV_RAD)", "COS_HALF_FOV")
    return prelude, kernels.replace("cache=True", "cache=False")


def layout_source(layout: str, parallel: bool = True) -> str:
    """The module text of the reference in `layout`; its kernel is `fused_pedestrian` (multi-threaded over the
    variants as the reference, or serial: `parallel`)."""
    prelude, kernels = _kernel_source()
    if not parallel:
        kernels = kernels.replace("@njit(parallel=True,", "@njit(parallel=False,")
    if layout == "constants":
        return prelude + kernels
    helper_end = kernels.index("@njit(parallel=")
    helper, kernel = kernels[:helper_end], kernels[helper_end:]
    kernel = kernel.replace("fused_pedestrian(cruise_mps,", "fused_pedestrian(S, X, cruise_mps,")
    for column, name in enumerate(SETTINGS):
        kernel = re.sub(rf"\b{name}\b", f"S[b, {column}]", kernel)
    if layout != "settings":
        loop = re.search(r"\n( +)for step in range\(n_steps\):\n", kernel)
        indent = loop.group(1) + "    "
        loads = ", ".join(
            f"int(X[b, {j}])" if name == "mode" else f"X[b, {j}] > 0.0" if name == "started" else f"X[b, {j}]"
            for j, name in enumerate(STATE)
        )
        stores = ", ".join(
            "float(mode)" if name == "mode" else "1.0 if started else 0.0" if name == "started" else name
            for name in STATE
        )
        targets = ", ".join(f"X[b, {j}]" for j in range(len(STATE)))
        kernel = kernel.replace(loop.group(0), f"{loop.group(0)}{indent}{', '.join(STATE)} = {loads}\n", 1)
        last = "\n        min_clearance[b], min_ttc[b], contact_s[b]"
        kernel = kernel.replace(last, f"\n{indent}{targets} = {stores}{last}", 1)
    if layout == "arrays":
        kernel = re.sub(r"S\[b, (\d+)\]", r"S[\1][b]", kernel)
        kernel = re.sub(r"X\[b, (\d+)\]", r"X[\1][b]", kernel)
    return prelude + helper + kernel


def load_layout(layout: str, folder: Path, parallel: bool = True):
    """The compiled `fused_pedestrian` of `layout`, from a module written into `folder`."""
    path = folder / f"reference_{layout}.py"
    path.write_text(layout_source(layout, parallel), encoding="utf-8")
    spec = importlib.util.spec_from_file_location(path.stem, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.fused_pedestrian


def arguments(layout: str, cruise_mps: np.ndarray, n_steps: int, dt: float) -> tuple[tuple, list[np.ndarray]]:
    """(the kernel's arguments in `layout` with fresh state, its three output arrays)."""
    out = [np.empty(cruise_mps.size) for _ in range(3)]
    if layout == "constants":
        return (cruise_mps, n_steps, dt, *out), out
    cos_half_fov = math.cos(fused_reference.SENSOR_HALF_FOV_RAD)
    values = [cos_half_fov if n == "COS_HALF_FOV" else getattr(fused_reference, n) for n in SETTINGS]
    table = np.tile(np.array(values, dtype=float), (cruise_mps.size, 1))
    state = np.zeros((cruise_mps.size, len(STATE)))
    state[:, STATE.index("x")] = fused_reference.EGO_START_X_M - fused_reference.REAR_TO_CENTRE_M
    state[:, STATE.index("y")] = fused_reference.EGO_Y_M
    state[:, STATE.index("hx")] = 1.0
    state[:, STATE.index("v")] = cruise_mps
    state[:, STATE.index("py")] = fused_reference.PED_Y_M
    state[:, [STATE.index("clear_min"), STATE.index("ttc_min"), STATE.index("first")]] = np.inf
    if layout == "arrays":
        table = tuple(np.ascontiguousarray(column) for column in table.T)
        state = tuple(np.ascontiguousarray(column) for column in state.T)
    return (table, state, cruise_mps, n_steps, dt, *out), out


def measure(batch: int, n_steps: int, repeats: int, dt: float = 0.01, parallel: bool = True) -> list[dict]:
    """Best wall time of each layout on the engine benchmark's cruise speeds; rows with ns a variant-step."""
    cruise = np.ascontiguousarray(speeds(batch))
    rows, reference = [], None
    with tempfile.TemporaryDirectory() as folder:
        for layout in LAYOUTS:
            kernel = load_layout(layout, Path(folder), parallel)
            kernel(*arguments(layout, cruise[:2], 2, dt)[0])  # compile
            best = math.inf
            for _ in range(repeats):
                args, out = arguments(layout, cruise, n_steps, dt)
                started = time.perf_counter()
                kernel(*args)
                best = min(best, time.perf_counter() - started)
            reference = reference or (best, out)
            rows.append(
                {
                    "layout": layout,
                    "seconds": best,
                    "ns_per_variant_step": best / (batch * n_steps) * 1e9,
                    "time_vs_constants": best / reference[0],
                    "identical": all(np.array_equal(a, b) for a, b in zip(out, reference[1], strict=True)),
                }
            )
    return rows


COLUMNS = {
    "layout": lambda r: r["layout"],
    "wall s": lambda r: f"{r['seconds']:.3f}",
    "ns a variant-step": lambda r: f"{r['ns_per_variant_step']:.1f}",
    "time / constants": lambda r: f"{r['time_vs_constants']:.2f}×",
    "identical results": lambda r: "yes" if r["identical"] else "NO",
}
"""The table's headings and each one's cell of a row of `measure`."""


if __name__ == "__main__":
    run_kernel_benchmark(__doc__.splitlines()[0], measure, "The fused reference in four layouts", COLUMNS)
