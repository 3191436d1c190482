"""The whole Euro NCAP catalogue grid (all families × speeds × day/night) as one batch: wall time and rate.

Run: python benchmarks/bench_ncap.py [--planner fsm] [--repeats 3] [--cli 5]

Times, best of the repeats and after a warm-up that loads the compiled kernels: building the Scenarios
from the protocol tables, the batch run (packing + stepping), and the assessment; for V2X off and on.
The goal on a 2-core machine: the whole 2023 grid in under 5 s, the whole 2026 grid (day and night) under 2 s
including process start (`time vrusim ncap --night`). `--cli N` measures exactly that: N runs of the installed
`vrusim ncap --night` (next to this Python; terminal output discarded), after one warm-up run that fills the
compiled-kernel cache; it prints the fastest and the median wall time.
"""

from __future__ import annotations

import argparse
import json
import resource
import statistics
import subprocess
import sys
import time
from pathlib import Path


def measure(planner: str, v2x: bool, repeats: int, protocol: str | None) -> dict:
    """Best-of-`repeats` timings of build, run and assessment for an edition's whole day + night grid."""
    from vrusim.ncap.assess import assess
    from vrusim.ncap.build import build_test
    from vrusim.ncap.editions import edition
    from vrusim.ncap.grid import run_tests, select
    from vrusim.ncap.rating2026 import assess_2026

    protocol = edition(protocol).name

    def points(rows: list[dict]) -> float:
        """Euro NCAP points: 2023 the total of the counted groups, 2026 the sum of the sub-elements."""
        if protocol == "2026":
            return sum(assess_2026(rows).sub_elements.values())
        return assess(rows).total

    tests = select(night=True, protocol=protocol)
    run_tests(tests[:3], planner=planner, v2x=v2x)  # warm-up: compiled kernels from the cache
    best = {"build_s": float("inf"), "total_s": float("inf"), "assess_s": float("inf")}
    steps = 0
    for _ in range(repeats):
        started = time.perf_counter()
        for test in tests:
            build_test(test, planner, v2x)
        best["build_s"] = min(best["build_s"], time.perf_counter() - started)
        started = time.perf_counter()
        result = run_tests(tests, planner=planner, v2x=v2x)
        best["total_s"] = min(best["total_s"], time.perf_counter() - started)
        started = time.perf_counter()
        total = points(result.rows)
        best["assess_s"] = min(best["assess_s"], time.perf_counter() - started)
        steps = result.run.steps
    return {
        "protocol": protocol,
        "planner": planner,
        "v2x": v2x,
        "tests": len(tests),
        "steps": steps,
        "build_s": round(best["build_s"], 3),
        "build_and_run_s": round(best["total_s"], 3),
        "assess_s": round(best["assess_s"], 3),
        "scenario_steps_per_s": round(len(tests) * steps / best["total_s"]),
        "euro_ncap_points": round(total, 3),
    }


def measure_cli(planner: str, protocol: str | None, runs: int) -> dict:
    """Wall seconds of whole `vrusim ncap --night` processes (start-up, build, run, assessment, terminal output)."""
    command = [str(Path(sys.executable).with_name("vrusim")), "ncap", "--night", "--planner", planner]
    if protocol is not None:
        command += ["--protocol", protocol]
    walls = []
    for _ in range(runs + 1):  # the first fills the kernel cache and is not counted
        started = time.perf_counter()
        subprocess.run(command, check=True, stdout=subprocess.DEVNULL)
        walls.append(time.perf_counter() - started)
    walls = walls[1:]
    return {"command": " ".join(command[1:]), "runs": runs, "min_s": min(walls), "median_s": statistics.median(walls)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--planner", default="fsm")
    parser.add_argument("--protocol", default=None, help="Euro NCAP edition (default: the default edition)")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--json", action="store_true", help="print the figures as JSON")
    parser.add_argument("--cli", type=int, default=0, metavar="N", help="time N whole `vrusim ncap --night` runs")
    args = parser.parse_args()
    if args.cli:
        wall = measure_cli(args.planner, args.protocol, args.cli)
        text = f"{wall['command']}: {wall['runs']} processes, fastest {wall['min_s']:.2f} s, "
        print(json.dumps(wall) if args.json else f"{text}median {wall['median_s']:.2f} s")
        return
    figures = [measure(args.planner, v2x, args.repeats, args.protocol) for v2x in (False, True)]
    peak_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    if args.json:
        print(json.dumps({"runs": figures, "peak_rss_mb": round(peak_mb, 1)}, indent=2))
        return
    for f in figures:
        print(
            f"protocol {f['protocol']}, planner {f['planner']}, V2X {'on ' if f['v2x'] else 'off'}: "
            f"{f['tests']} tests x {f['steps']} steps "
            f"in {f['build_and_run_s']:.2f} s (build {f['build_s']:.2f} s), assessment {f['assess_s']:.3f} s, "
            f"{f['scenario_steps_per_s']:,} scenario-steps/s, {f['euro_ncap_points']} Euro NCAP points"
        )
    print(f"peak RSS {peak_mb:.0f} MB")


if __name__ == "__main__":
    main()
