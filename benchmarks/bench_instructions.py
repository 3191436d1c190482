"""Executed instructions per variant-step of the compiled engine and of the fused reference kernel, counted by
Valgrind (issue 20): a measure that, unlike wall time, does not drift with this VM's speed.

Run: python benchmarks/bench_instructions.py [--planners fsm none aeb predictive] [--batch 2000] [--steps 1000]
                                             [--reference-batch 20000] [--json]

Each workload runs under `valgrind --tool=cachegrind --cache-sim=no` in fresh processes (one Numba thread,
`PYTHONHASHSEED=0`): a warm-up of one step (not counted: it compiles the kernels for Valgrind's CPU if they are
not cached yet), two runs of one step and one of `--steps` steps. The difference between the long run's
instruction count and the mean of the short runs', divided by batch × (steps − 1), is the mean instructions of
one variant-step over the horizon the engine benchmark times: start-up, imports, kernel loading and packing are
the same in every run and cancel out. They cancel only to within a few million instructions, so the table also
gives the two short runs' difference on the same scale ("start-up spread"); a larger batch shrinks it. The
reference runs a larger batch (`--reference-batch`), as its steps are short and its start-up spread larger.

Workloads: the engine benchmark's batch (`bench_engine.packed_batch`: the paper pedestrian case, V2X on, stop
rules off) through `simulate(batch, compiled=True)` for each planner, and `fused_reference.run_reference` on
the same cruise speeds. Valgrind's virtual CPU is not this machine's, so Numba compiles its kernels for it once
(minutes, then cached beside the native ones) and their code differs slightly from the native code.

The counts tell where a step's time goes: on this workload the engine and the reference retire about the same
instructions per cycle, so their speed ratio is about their instruction ratio. Instructions on a dependent chain
(the route evaluations of a Newton projection) cost more than their share (docs/architecture.md).
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from bench_engine import DT_S, PLANNERS, packed_batch
from machine import header, machine, markdown_table

REFERENCE = "reference"


def run_workload(workload: str, size: int, steps: int) -> None:
    """Child process: run one workload (a planner's compiled engine run, or the reference) once, single-threaded."""
    import numba
    import numpy as np

    numba.set_num_threads(1)
    params = packed_batch(size, steps * DT_S, "fsm" if workload == REFERENCE else workload)
    if workload == REFERENCE:
        from fused_reference import run_reference

        run_reference(np.ascontiguousarray(params.cruise_speed_mps), steps, DT_S)
        return
    from vrusim.engine.simulate import simulate

    out = simulate(params, compiled=True)
    if out.steps != steps:
        raise SystemExit(f"the engine ran {out.steps} steps instead of {steps}")


def summary_count(cachegrind_out: str) -> int:
    """The total instruction count (`summary:` line) of a cachegrind output file's text."""
    for line in cachegrind_out.splitlines():
        if line.startswith("summary:"):
            return int(line.split()[1])
    raise ValueError("no 'summary:' line in the cachegrind output")


def per_step(counts_one: tuple[int, int], count_all: int, size: int, steps: int) -> tuple[float, float]:
    """Mean instructions of one variant-step from the counts of two runs of one step and one of `steps` steps, and
    the two short runs' difference on the same scale (the start-up's spread)."""
    scale = size * (steps - 1)
    first, second = counts_one
    return (count_all - (first + second) / 2) / scale, abs(first - second) / scale


def count(workload: str, size: int, steps: int) -> int:
    """Instructions executed by a fresh process running `workload` for `steps` steps under cachegrind."""
    with tempfile.TemporaryDirectory() as folder:
        out = Path(folder) / "cachegrind.out"
        command = [
            "valgrind", "--tool=cachegrind", "--cache-sim=no", f"--cachegrind-out-file={out}",
            sys.executable, str(Path(__file__).resolve()), "--child", workload, "--batch", str(size),
            "--steps", str(steps),
        ]  # fmt: skip
        env = {**os.environ, "PYTHONHASHSEED": "0", "NUMBA_NUM_THREADS": "1"}
        done = subprocess.run(command, env=env, capture_output=True, text=True, check=False)
        if done.returncode != 0:
            raise SystemExit(f"{workload} failed under valgrind:\n{done.stderr[-2000:]}")
        return summary_count(out.read_text())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--planners", nargs="+", choices=PLANNERS, default=["fsm"], help="default: fsm")
    parser.add_argument("--batch", type=int, default=2000, help="variants per run (default 2,000)")
    parser.add_argument(
        "--reference-batch", type=int, default=20_000, help="variants of the reference's runs (default 20,000)"
    )
    parser.add_argument("--steps", type=int, default=1000, help="steps of the longer run (default 1,000)")
    parser.add_argument("--json", action="store_true", help="print the rows as JSON")
    parser.add_argument("--child", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        run_workload(args.child, args.batch, args.steps)
        return
    if args.batch < 1 or args.reference_batch < 1 or args.steps < 2:
        parser.error("--batch, --reference-batch: expected positive integers; --steps: expected an integer >= 2")
    if shutil.which("valgrind") is None:
        print(
            "bench_instructions: valgrind is not on PATH (Debian / Ubuntu: apt-get install valgrind)", file=sys.stderr
        )
        raise SystemExit(2)
    rows = []
    for workload in [*args.planners, REFERENCE]:
        size = args.reference_batch if workload == REFERENCE else args.batch
        count(workload, size, 1)  # warm-up: compiles the kernels for Valgrind's CPU once
        ones = count(workload, size, 1), count(workload, size, 1)
        mean, spread = per_step(ones, count(workload, size, args.steps), size, args.steps)
        rows.append(
            {"workload": workload, "batch": size, "instructions_per_step": round(mean, 1),
             "startup_spread": round(spread, 1)}
        )  # fmt: skip
    reference = rows[-1]["instructions_per_step"]
    if args.json:
        print(json.dumps({"machine": machine(), "steps": args.steps, "rows": rows}, indent=2))
        return
    print(header({**machine(), "numba_threads": 1}))
    print(f"runs of 1 and {args.steps:,} steps, one thread, under valgrind (cachegrind)\n")
    table = [
        [
            r["workload"], f"{r['batch']:,}", f"{r['instructions_per_step']:,.0f}", f"±{r['startup_spread']:,.1f}",
            f"{r['instructions_per_step'] / reference:.2f}",
        ]
        for r in rows
    ]  # fmt: skip
    print(markdown_table(["workload", "B", "instructions / variant-step", "start-up spread", "× reference"], table))


if __name__ == "__main__":
    main()
