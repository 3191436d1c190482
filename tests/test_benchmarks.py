"""The benchmark scripts run, at tiny sizes (they are never timed here), and the engine benchmark's cheap batch is
exactly what `pack` makes from validated Scenarios."""

from __future__ import annotations

import dataclasses
import json
import re
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest

BENCHMARKS = Path(__file__).resolve().parents[1] / "benchmarks"
sys.path.insert(0, str(BENCHMARKS))

import bench_cli  # noqa: E402
import bench_engine  # noqa: E402
import bench_instructions  # noqa: E402


def _differences(a: Any, b: Any, path: str = "params") -> list[str]:
    """Paths where two packed batches differ (arrays by dtype, shape and values; objects member by member)."""
    if isinstance(a, np.ndarray):
        same = a.dtype == b.dtype and a.shape == b.shape and np.array_equal(a, b, equal_nan=a.dtype.kind == "f")
        return [] if same else [path]
    if dataclasses.is_dataclass(a):
        members = {f.name: (getattr(a, f.name), getattr(b, f.name)) for f in dataclasses.fields(a)}
    elif isinstance(a, tuple) and hasattr(a, "_fields"):
        members = {name: (getattr(a, name), getattr(b, name)) for name in a._fields}
    elif hasattr(a, "__dict__") and type(a) is type(b):
        members = {name: (value, vars(b)[name]) for name, value in vars(a).items()}
    else:
        return [] if a == b else [path]
    return [d for name, (x, y) in members.items() for d in _differences(x, y, f"{path}.{name}")]


@pytest.mark.parametrize("planner", bench_engine.PLANNERS)
def test_tiled_batch_is_the_packed_scenarios(planner: str) -> None:
    from vrusim.sim.params import pack

    tiled = bench_engine.packed_batch(4, 0.5, planner)
    assert _differences(pack(bench_engine.batch(4, 0.5, planner)), tiled) == []
    assert tiled.planner_names == [planner] * 4 and len(set(tiled.cruise_speed_mps)) == 4


def _script(name: str, *args: str) -> str:
    done = subprocess.run([sys.executable, str(BENCHMARKS / name), *args], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    return done.stdout


def test_engine_benchmark_runs() -> None:
    out = json.loads(_script("bench_engine.py", "--sizes", "2", "--planners", "fsm", "--steps", "5", "--repeats",
                             "1", "--reference-sizes", "2", "--json"))  # fmt: skip
    (row,) = out["rows"]
    assert row["steps"] == 5 and row["auto_steps_per_s"] > 0 and row["reference_steps_per_s"] > 0
    assert out["machine"]["cores"] >= 1


def test_traced_run_benchmark_runs() -> None:
    out = json.loads(_script("bench_traced_run.py", "--runs", "1", "--planners", "none", "--json"))
    assert len(out["rows"]) == 3  # the paper cases
    assert all(row["identical"] and row["steps"] > 0 and row["compiled_median_s"] > 0 for row in out["rows"])


def test_sweep_benchmark_runs() -> None:
    out = _script("bench_sweep.py", "--goal", "20", "--warmup", "0")
    assert "| 20 |" in out and "goal >= 20,000" in out


def test_cli_benchmark_parts(tmp_path: Path) -> None:
    """The timing and the cold-start check, with a stand-in for vrusim (the real commands take seconds)."""
    stand_in = [sys.executable, "-c", "import sys; sys.stderr.write('Compiling kernels (once)\\n')"]
    row = bench_cli.warm("stand-in", stand_in, 2, 60.0)
    assert row["runs"] == 2 and 0 < row["min_s"] <= row["median_s"] and row["met"]
    cold = bench_cli.cold(stand_in, bench_cli.PAPER[0])
    assert cold["says_compiling"] and cold["stderr_line"] == "Compiling kernels (once)"


@pytest.mark.parametrize("workload", ["fsm", "predictive", bench_instructions.REFERENCE])
def test_instruction_benchmark_workloads_run(workload: str) -> None:
    """The processes the instruction count runs under valgrind run (here without it, at a tiny size)."""
    _script("bench_instructions.py", "--child", workload, "--batch", "2", "--steps", "3")


def test_instruction_count_arithmetic() -> None:
    text = "desc: --cache-sim=no\ncmd: python x.py\nevents: Ir\nfl=???\n0 12\nsummary: 123456\n"
    assert bench_instructions.summary_count(text) == 123_456
    with pytest.raises(ValueError, match="summary"):
        bench_instructions.summary_count("events: Ir\n")
    # two runs of 1 step and one of 11: 10 extra steps of 4 variants cost 40 x 1,500 instructions
    assert bench_instructions.per_step((999_980, 1_000_020), 1_060_000, 4, 11) == (1_500.0, 1.0)


def test_instruction_benchmark_without_valgrind(tmp_path: Path) -> None:
    """Without valgrind the benchmark says what is missing and exits with 2, no traceback."""
    done = subprocess.run(
        [sys.executable, str(BENCHMARKS / "bench_instructions.py"), "--steps", "5"],
        capture_output=True, text=True, timeout=120, env={"PATH": str(tmp_path)},  # an empty folder: no valgrind
    )  # fmt: skip
    assert done.returncode == 2 and "valgrind is not on PATH" in done.stderr and "Traceback" not in done.stderr


def test_reference_layouts_substitute_every_setting_and_change_no_result() -> None:
    import reference_layouts

    kernel = reference_layouts.layout_source("settings").split("def fused_pedestrian", 1)[1]
    assert not [name for name in reference_layouts.SETTINGS if re.search(rf"\b{name}\b", kernel)]
    arrays = reference_layouts.layout_source("arrays").split("def fused_pedestrian", 1)[1]
    assert "S[0][b]" in arrays and "X[0][b]" in arrays and "[b, " not in arrays
    rows = reference_layouts.measure(batch=40, n_steps=400, repeats=1, parallel=False)  # serial: compiles faster
    assert [row["layout"] for row in rows] == list(reference_layouts.LAYOUTS)
    assert all(row["identical"] for row in rows)


def test_simd_lanes_orders_give_the_same_results_and_only_one_is_vectorised() -> None:
    """Both loop orders of the contact geometry give bit-identical minima; the variants-innermost order holds packed
    double instructions and the per-variant one none (on a CPU with AVX2, where LLVM uses ymm / zmm registers)."""
    import simd_lanes

    rows = simd_lanes.measure(batch=40, n_steps=1000, repeats=1)
    assert [row["order"] for row in rows] == list(simd_lanes.ORDERS)
    assert all(row["identical"] for row in rows)
    state = simd_lanes._state(40)
    simd_lanes.per_variant(*state, 1000)
    min_clearance = state[3]
    assert (min_clearance < 0.0).any() and (min_clearance > 0.0).any()  # some egos hit the pedestrian, some miss
    cpu = Path("/proc/cpuinfo")
    if cpu.exists() and " avx2" in cpu.read_text():
        assert rows[0]["packed_instructions"] == 0 < rows[1]["packed_instructions"]
