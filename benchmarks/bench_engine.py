"""Engine throughput on the paper's pedestrian scenario for each built-in planner: scenario-steps per second of
both engine paths, peak memory, and the fused reference kernel's rate in the same run (issue 20).

Run: python benchmarks/bench_engine.py [--sizes 1 100 10000 100000] [--planners fsm none aeb predictive]
                                       [--repeats 3] [--steps 1000] [--json]

Workload: B variants of the paper pedestrian case (He et al., CPSI 2025, case (i)) with V2X on, stop rules off
and a 400 m route, so every variant is stepped the whole time; the ego's cruise (and start) speed is spread over
12–18 m/s so that variants differ; `--steps` steps at dt 0.01 s (1,000: 10 s simulated). Every planner runs the
same batch with its default parameters (the FSM with the case's own, `emergency_decel_mps2: 6`).

Building the batch: one Scenario is validated and packed, its packed arrays are tiled B times
(`vrusim.sim.compaction.take` with an index of zeros), and the two packed fields that depend on the cruise speed,
`cruise_speed_mps` and `start_speed_mps` (the start speed is the cruise speed when `ego.initial_speed_mps` is
unset), are written with the spread. This gives exactly the arrays `pack` makes from B validated Scenarios
(`batch`; tests/test_benchmarks.py checks it field by field) in milliseconds instead of about 8 s for 10^5
pydantic models.

Engine paths: `simulate(batch, compiled=None)` ("auto": a built-in planner's compiled fused step when the batch
allows it, else the per-step path) and `simulate(batch, compiled=False)` (the per-step Python path). Rate =
B × steps / wall time of `simulate` on the packed batch, best of the repeats, the paths alternating; a warm-up
of 2 steps at the same B first loads every compiled kernel that size uses (serial below
`vrusim.kernels.PARALLEL_MIN_BATCH`, multi-threaded from it). Each (planner, B) runs in a fresh subprocess, so
its peak resident set (both paths; the reference too where it runs) does not inherit another's. Before them,
`vrusim compile` compiles the benchmarked planners' kernels into the cache, so that no measuring process compiles
(compiling the multi-threaded kernels inside one once counted numba's and LLVM's memory in the FSM's B = 10^5 peak:
848 MB instead of 463).

Reference: for the FSM at each B in `--reference-sizes` (default 10^4) the same subprocess also times the fused
Numba kernel of `fused_reference.py` on the same cruise speeds, interleaved with the engine runs, and the table
gives engine / reference (the issue's goal: at least 40 % at B = 10^4 with the auto path).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import resource
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from machine import header, machine, markdown_table

ROOT = Path(__file__).resolve().parents[1]
SCENARIO = ROOT / "scenarios" / "paper" / "pedestrian_crossing.yaml"
PLANNERS = ("fsm", "none", "aeb", "predictive")
DT_S = 0.01
SPEEDS_MPS = (12.0, 18.0)
GOAL = 0.40
"""Issue 20: the engine (auto path, FSM) at B = 10^4 reaches at least this fraction of the reference's rate."""


def scenario(duration_s: float, planner: str = "fsm"):
    """The paper pedestrian case with V2X on, stop rules off, a 400 m route, run by `planner` (validated)."""
    from vrusim.scenario.loading import load_scenario
    from vrusim.scenario.settings import with_settings

    base = with_settings(load_scenario(SCENARIO), planner=planner, v2x=True)
    return base.replace(
        **{
            "sim.duration_s": duration_s,
            "sim.stop_on_collision": False,
            "sim.stop_at_route_end": False,
            "ego.route.length_m": 400.0,
        }
    )


def speeds(size: int) -> np.ndarray:
    """The cruise speeds of B variants, m/s: evenly spread over `SPEEDS_MPS`."""
    return np.linspace(*SPEEDS_MPS, size)


def batch(size: int, duration_s: float, planner: str = "fsm") -> list:
    """B validated Scenarios of the workload, one per cruise speed (slow for large B: the reference for
    `packed_batch`)."""
    base = scenario(duration_s, planner)
    return [base.replace(**{"ego.cruise_speed_mps": float(v)}) for v in speeds(size)]


def packed_batch(size: int, duration_s: float, planner: str = "fsm"):
    """The packed arrays of `batch(size, duration_s, planner)`, built from one packed Scenario tiled B times."""
    from vrusim.sim.compaction import take
    from vrusim.sim.params import pack

    one = pack([scenario(duration_s, planner)])
    tiled = take(one, np.zeros(size, dtype=np.int64))
    cruise = speeds(size)
    # `pack` reads both from the Scenario: the start speed is the cruise speed (ego.initial_speed_mps unset)
    return dataclasses.replace(tiled, cruise_speed_mps=cruise, start_speed_mps=cruise.copy())


def shortened(params, steps: int):
    """`params` cut to `steps` steps (the warm-up that loads the compiled kernels of this batch size)."""
    duration = np.full(params.size, steps * params.dt_s)
    return dataclasses.replace(params, n_steps=steps, duration_s=duration)


def measure(planner: str, size: int, repeats: int, steps: int, reference: bool) -> dict:
    """Time `repeats` alternating runs of both engine paths (and the reference) on one batch; best figures."""
    from vrusim.engine.simulate import simulate

    started = time.perf_counter()
    params = packed_batch(size, steps * DT_S, planner)
    build_s = time.perf_counter() - started
    runs = {
        "auto": lambda: simulate(params, compiled=None),
        "per_step": lambda: simulate(params, compiled=False),
    }
    warm = shortened(params, 2)
    simulate(warm, compiled=None)
    simulate(warm, compiled=False)
    if reference:
        from fused_reference import run_reference

        cruise = np.ascontiguousarray(params.cruise_speed_mps)
        run_reference(cruise[:2], 2, DT_S)  # compile / load from the cache
        runs["reference"] = lambda: run_reference(cruise, steps, DT_S)
    best = dict.fromkeys(runs, float("inf"))
    n_steps = params.n_steps
    for _ in range(repeats):
        for name, run in runs.items():
            start = time.perf_counter()
            out = run()
            best[name] = min(best[name], time.perf_counter() - start)
            if name != "reference":
                n_steps = out.steps
            del out
    row = {
        "planner": planner,
        "batch": size,
        "steps": n_steps,
        "build_s": round(build_s, 4),
        "peak_rss_mb": round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024, 1),
    }
    for name, seconds in best.items():
        row[f"{name}_s"] = round(seconds, 4)
        row[f"{name}_steps_per_s"] = round(size * (steps if name == "reference" else n_steps) / seconds)
    return row


def _rate(value: float) -> str:
    """Scenario-steps/s for a table: `37.6 k`, `10.52 M`."""
    return f"{value / 1e6:.2f} M" if value >= 1e6 else f"{value / 1e3:.1f} k"


def table(rows: list[dict]) -> str:
    """The engine table: one row per (planner, B)."""
    columns = ["planner", "B", "steps", "build s", "auto s", "auto steps/s", "per-step s", "per-step steps/s",
               "auto / per-step", "peak RSS MB"]  # fmt: skip
    cells = [
        [
            r["planner"],
            f"{r['batch']:,}",
            r["steps"],
            f"{r['build_s']:.3f}",
            f"{r['auto_s']:.3f}",
            _rate(r["auto_steps_per_s"]),
            f"{r['per_step_s']:.3f}",
            _rate(r["per_step_steps_per_s"]),
            f"{r['auto_steps_per_s'] / r['per_step_steps_per_s']:.2f}×",
            f"{r['peak_rss_mb']:.0f}",
        ]
        for r in rows
    ]
    return markdown_table(columns, cells, right=set(range(1, len(columns))))


def reference_table(rows: list[dict]) -> str:
    """The fused reference against the FSM engine, measured in the same processes."""
    columns = ["B", "reference s", "reference steps/s", "engine auto / reference", "engine per-step / reference"]
    cells = []
    for r in rows:
        ratio = r["auto_steps_per_s"] / r["reference_steps_per_s"]
        verdict = "met" if ratio >= GOAL else "not met"
        cells.append(
            [
                f"{r['batch']:,}",
                f"{r['reference_s']:.3f}",
                _rate(r["reference_steps_per_s"]),
                f"{ratio:.1%} (goal {GOAL:.0%}: {verdict})",
                f"{r['per_step_steps_per_s'] / r['reference_steps_per_s']:.1%}",
            ]
        )
    return markdown_table(columns, cells)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sizes", type=int, nargs="+", default=[1, 100, 10_000, 100_000])
    parser.add_argument("--planners", nargs="+", default=list(PLANNERS), choices=PLANNERS)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--steps", type=int, default=1000, help="steps per run (dt 0.01 s)")
    parser.add_argument("--reference-sizes", type=int, nargs="*", default=[10_000], help="B of the reference runs")
    parser.add_argument("--json", action="store_true", help="print the rows and the machine as JSON, not tables")
    parser.add_argument("--one", nargs=2, metavar=("PLANNER", "B"), help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.one is not None:
        planner, size = args.one[0], int(args.one[1])
        reference = planner == "fsm" and size in args.reference_sizes
        print(json.dumps(measure(planner, size, args.repeats, args.steps, reference)))
        return
    warm_up = [sys.executable, "-m", "vrusim", "compile", "--planner", ",".join(args.planners)]
    subprocess.run([*warm_up, "--part", "compiled,per-step,threaded"], capture_output=True, check=True)
    rows = []
    for planner in args.planners:
        for size in args.sizes:
            command = [sys.executable, __file__, "--one", planner, str(size), "--repeats", str(args.repeats)]
            command += ["--steps", str(args.steps), "--reference-sizes", *map(str, args.reference_sizes)]
            out = subprocess.run(command, capture_output=True, text=True)
            if out.returncode != 0:
                raise SystemExit(f"{planner} at B = {size} failed:\n{out.stderr}")
            rows.append(json.loads(out.stdout))
    info = machine()
    if args.json:
        print(json.dumps({"machine": info, "rows": rows}, indent=2))
        return
    print(f"Engine throughput, paper pedestrian case (V2X on, stop rules off), best of {args.repeats}")
    print(f"{header(info)}\n")
    print(table(rows))
    with_reference = [r for r in rows if "reference_s" in r]
    if with_reference:
        print("\nFused reference kernel (benchmarks/fused_reference.py) against the FSM engine, same processes\n")
        print(reference_table(with_reference))


if __name__ == "__main__":
    main()
