"""One scenario's traced run in-process: `vrusim.run` of each paper case, which records its trace by default, on
the compiled step (one variant's trace is written inside the kernel) and on the per-step path.

Run: python benchmarks/bench_traced_run.py [--runs 15] [--planners fsm none aeb predictive] [--json]

Each (case, planner) runs once unmeasured (loading the compiled kernels), then `--runs` times on each path in
turn; the table gives the median and fastest wall time of `simulate([scenario], trace=True)` with `compiled=None`
(what `vrusim.run` does) and with `compiled=False`, and checks that both traces are the same, byte for byte.
"""

from __future__ import annotations

import argparse
import json
import statistics
import time
from pathlib import Path

from machine import header, machine, markdown_table

ROOT = Path(__file__).resolve().parents[1]
PAPER = sorted((ROOT / "scenarios" / "paper").glob("*.yaml"))
PLANNERS = ("fsm", "none", "aeb", "predictive")


def timed(function, runs: int) -> tuple[float, float, object]:
    """(median s, fastest s, last result) of `runs` calls."""
    seconds, result = [], None
    for _ in range(runs):
        started = time.perf_counter()
        result = function()
        seconds.append(time.perf_counter() - started)
    return statistics.median(seconds), min(seconds), result


def same_trace(a: dict, b: dict) -> bool:
    """Both traces have the same columns, dtypes, shapes and bytes."""
    return list(a) == list(b) and all(
        (a[k].dtype, a[k].shape) == (b[k].dtype, b[k].shape) and a[k].tobytes() == b[k].tobytes() for k in a
    )


def measure(case: Path, planner: str, runs: int) -> dict:
    from vrusim.engine.simulate import simulate
    from vrusim.scenario.loading import load_scenario
    from vrusim.scenario.settings import with_settings

    scenario = with_settings(load_scenario(case), planner=planner)
    paths = {"compiled": None, "per_step": False}
    for compiled in paths.values():
        simulate([scenario], trace=True, compiled=compiled)
    row: dict = {"case": case.stem, "planner": planner}
    traces = {}
    for name, compiled in paths.items():
        median, best, run = timed(lambda c=compiled: simulate([scenario], trace=True, compiled=c), runs)
        row[f"{name}_median_s"], row[f"{name}_best_s"], traces[name] = median, best, run.trace
        row["steps"] = run.steps
    row["identical"] = same_trace(traces["compiled"], traces["per_step"])
    return row


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=15)
    parser.add_argument("--planners", nargs="+", default=list(PLANNERS), choices=PLANNERS)
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    info = machine()
    rows = [measure(case, planner, args.runs) for case in PAPER for planner in args.planners]
    if args.json:
        print(json.dumps({"machine": info, "rows": rows}, indent=2))
        return
    print("One scenario's traced run, in-process (`vrusim.run` of one scenario)")
    print(header(info))
    print()
    table = [
        [
            r["case"], r["planner"], str(r["steps"]), f"{r['compiled_median_s'] * 1e3:.1f}",
            f"{r['per_step_median_s'] * 1e3:.1f}", f"{r['per_step_median_s'] / r['compiled_median_s']:.1f}×",
            "yes" if r["identical"] else "NO",
        ]
        for r in rows
    ]  # fmt: skip
    columns = ["case", "planner", "steps", "compiled ms", "per-step ms", "per-step / compiled", "same trace"]
    print(markdown_table(columns, table, right={2, 3, 4, 5}))


if __name__ == "__main__":
    main()
