"""The simulated Euro NCAP 2026 laboratory verification (FC26 §4): wall time of the Monte Carlo for one planner.

Run: python benchmarks/bench_verification.py [--planner aeb] [--draws 1000] [--perturbations 16]

Times, after a warm-up that loads the compiled kernels: running and assessing the whole 2026 grid (day and
night), then `Rated2026.verify`: every eligible cell's tolerance runs simulated in one batch and `draws` lab
samples drawn from them. The goal on a 2-core machine is 1,000 draws under 30 s.
"""

from __future__ import annotations

import argparse
import json
import resource
import time


def measure(planner: str, draws: int, perturbations: int) -> dict:
    """Timings and results of one grid run and its verification Monte Carlo."""
    from vrusim.ncap.grid import select
    from vrusim.ncap.rated2026 import rate_2026

    tests = select(night=True, protocol="2026")
    rate_2026(tests[:3], planner=planner)  # warm-up: compiled kernels from the cache
    started = time.perf_counter()
    rated = rate_2026(tests, planner=planner)
    grid_s = time.perf_counter() - started
    started = time.perf_counter()
    report = rated.verify(draws, seed=0, perturbations=perturbations)
    verify_s = time.perf_counter() - started
    return {
        "planner": planner,
        "tests": len(tests),
        "grid_s": round(grid_s, 3),
        "draws": draws,
        "perturbations_per_cell": perturbations,
        "cells_verified": len(report.pass_probability),
        "tolerance_runs": len(report.pass_probability) * perturbations,
        "verify_s": round(verify_s, 3),
        "sub_elements": {
            name: {"predicted": round(rated.assessment.sub_elements[name], 3), **vars(spread)}
            for name, spread in report.sub_elements.items()
        },
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--planner", default="aeb")
    parser.add_argument("--draws", type=int, default=1000)
    parser.add_argument("--perturbations", type=int, default=16)
    parser.add_argument("--json", action="store_true", help="print the figures as JSON")
    args = parser.parse_args()
    figures = measure(args.planner, args.draws, args.perturbations)
    figures["peak_rss_mb"] = round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024, 1)
    if args.json:
        print(json.dumps(figures, indent=2))
        return
    print(
        f"planner {figures['planner']}: {figures['tests']} tests run and assessed in {figures['grid_s']:.2f} s; "
        f"verification: {figures['cells_verified']} cells x {figures['perturbations_per_cell']} tolerance runs "
        f"({figures['tolerance_runs']} simulations), {figures['draws']} lab draws in {figures['verify_s']:.2f} s"
    )
    for name, spread in figures["sub_elements"].items():
        print(
            f"  {name}: predicted {spread['predicted']:.2f}, after verification {spread['mean']:.2f} ± "
            f"{spread['std']:.2f} (5-95 %: {spread['p5']:.2f}-{spread['p95']:.2f})"
        )
    print(f"peak RSS {figures['peak_rss_mb']:.0f} MB")


if __name__ == "__main__":
    main()
