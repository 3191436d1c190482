"""Sweep throughput end to end (process start, planning, simulation, Parquet storage) and peak memory, on the
pedestrian Monte Carlo of `sweeps/pedestrian_monte_carlo.yaml` (V2X on with uncertain latency and loss).

Run: python benchmarks/bench_sweep.py [--variants 10000] [--batch-sizes 250 1000 2500 5000] [--full] [--json]
     python benchmarks/bench_sweep.py --goal            # issue 20's check: the 100,000-variant Monte Carlo

Each configuration runs `python -m vrusim sweep SPEC [--workers W] --json` in its own process (the spec with
`samples` and `batch_size` set, its base the paper pedestrian case). Two rates: "wall", variants / wall time of
the whole command from its start to its exit (Python start-up, imports, spawning the workers, planning,
simulation, storage: what a user waits for), and "sweep", the rate the command reports for its sweep alone.
Peak memory is the largest sum of the resident sets of the command and its worker processes, sampled every 20 ms
(an upper bound: pages of shared libraries count once per process). A warm-up sweep first fills the
compiled-kernel cache, so no row pays for compiling.

Tables: rate against batch size (the command's default workers: for this spec, the calling process on every
core); against workers (batch 2,500, or a quarter of the variants if
fewer: 1 process on 1 core, 1 process with all cores as Numba threads, 2 processes; scaling efficiency =
rate / (workers × 1-core rate)); with `--full`, peak memory for 10^4 and 10^5 variants. `--goal` runs only the
issue's check: the spec as shipped (100,000 variants, batch 2,500) with the default workers, against the goals
≥ 20,000 variants/s wall with process start and peak ≤ 600 MB (`--goal N`: N variants instead, e.g. to try the
script; `--repeats R`: R runs).
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import psutil
import yaml

from machine import header, machine, markdown_table

ROOT = Path(__file__).resolve().parents[1]
SPEC = ROOT / "sweeps" / "pedestrian_monte_carlo.yaml"
GOAL_VARIANTS, GOAL_RATE, GOAL_PEAK_MB = 100_000, 20_000, 600
"""Issue 20: the 100,000-variant Monte Carlo at >= 20,000 variants/s wall on 2 cores, peak <= 600 MB."""
SAMPLE_S = 0.02


def _tree_rss(process: psutil.Process) -> int:
    total = 0
    with contextlib.suppress(psutil.Error):  # the command or a worker that just ended
        for member in [process, *process.children(recursive=True)]:
            with contextlib.suppress(psutil.Error):
                total += member.memory_info().rss
    return total


def run(variants: int, batch_size: int, workers: int, threads: int | None = None) -> dict:
    """One sweep in a fresh process (`workers` 0: the command's default): wall time from its start to its exit,
    reported rate, peak memory of the process tree."""
    data = yaml.safe_load(SPEC.read_text())
    data.update(samples=variants, batch_size=batch_size, base=str(ROOT / "scenarios/paper/pedestrian_crossing.yaml"))
    with tempfile.TemporaryDirectory() as folder:
        spec = Path(folder) / "spec.yaml"
        spec.write_text(yaml.safe_dump(data))
        # as bench_cli: Python keeps its bytecode cache, as an installed copy does after its first run
        env = {name: value for name, value in os.environ.items() if name != "PYTHONDONTWRITEBYTECODE"}
        if threads is not None:
            env["NUMBA_NUM_THREADS"] = str(threads)
        command = [sys.executable, "-m", "vrusim", "sweep", str(spec), "--out", f"{folder}/out"]
        command += (["--workers", str(workers)] if workers else []) + ["--json"]
        started = time.perf_counter()
        child = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
        peak = 0
        watcher = psutil.Process(child.pid)

        def sample() -> None:
            nonlocal peak
            while child.poll() is None:
                peak = max(peak, _tree_rss(watcher))
                time.sleep(SAMPLE_S)

        thread = threading.Thread(target=sample)
        thread.start()
        stdout, stderr = child.communicate()
        wall_s = time.perf_counter() - started
        thread.join()
        if child.returncode != 0:
            raise SystemExit(stderr)
        outcome = json.loads(stdout)
        stored_mb = sum(p.stat().st_size for p in Path(folder, "out").rglob("*.parquet")) / 1e6
    return {
        "variants": variants,
        "batch_size": batch_size,
        "workers": workers,
        "threads": threads,
        "wall_s": round(wall_s, 3),
        "sweep_s": outcome["elapsed_s"],
        "wall_variants_per_s": round(variants / wall_s),
        "sweep_variants_per_s": round(outcome["variants_per_s"]),
        "peak_rss_mb": round(peak / 1e6),
        "stored_mb": round(stored_mb, 1),
    }


def table(rows: list[dict]) -> str:
    """The rows as a markdown table."""
    columns = ["variants", "batch", "workers", "threads", "wall s", "sweep s", "variants/s wall", "variants/s sweep",
               "peak RSS MB", "Parquet MB"]  # fmt: skip
    cells = [
        [
            f"{r['variants']:,}",
            f"{r['batch_size']:,}",
            r["workers"] or "default",
            r["threads"] or "all",
            f"{r['wall_s']:.2f}",
            f"{r['sweep_s']:.2f}",
            f"{r['wall_variants_per_s']:,}",
            f"{r['sweep_variants_per_s']:,}",
            r["peak_rss_mb"],
            r["stored_mb"],
        ]
        for r in rows
    ]
    return markdown_table(columns, cells)


def goal_verdict(row: dict) -> str:
    """Issue 20's sweep goals against one run."""
    rate = "met" if row["wall_variants_per_s"] >= GOAL_RATE else "not met"
    memory = "met" if row["peak_rss_mb"] <= GOAL_PEAK_MB else "not met"
    return (
        f"{row['variants']:,} variants in {row['wall_s']:.2f} s wall: {row['wall_variants_per_s']:,} variants/s "
        f"(goal >= {GOAL_RATE:,}: {rate}), peak {row['peak_rss_mb']} MB (goal <= {GOAL_PEAK_MB}: {memory})"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--variants", type=int, default=10_000, help="variants of the batch and worker tables")
    parser.add_argument("--batch-sizes", type=int, nargs="+", default=[250, 1000, 2500, 5000])
    parser.add_argument("--full", action="store_true", help="also the 10^4 / 10^5 memory table (minutes)")
    parser.add_argument("--goal", type=int, nargs="?", const=GOAL_VARIANTS, metavar="N", help="only issue 20's check")
    parser.add_argument("--repeats", type=int, default=1, help="runs of the --goal check")
    parser.add_argument("--warmup", type=int, default=500, help="variants of the warm-up sweep (0: none)")
    parser.add_argument("--json", action="store_true", help="print the rows and the machine as JSON, not tables")
    args = parser.parse_args()
    info = machine()
    if args.warmup:
        run(args.warmup, max(1, args.warmup // 2), 1)  # fills the compiled-kernel cache
    sections: list[tuple[str, list[dict]]] = []
    if args.goal is not None:
        spec = yaml.safe_load(SPEC.read_text())
        rows = [run(args.goal, spec["batch_size"], 0) for _ in range(args.repeats)]
        sections.append(
            (f"Issue 20's check: {args.goal:,}-variant Monte Carlo, default workers, wall with start", rows)
        )
    else:
        n = args.variants
        batches = [run(n, size, 0) for size in args.batch_sizes]
        sections.append((f"Rate against batch size ({n:,} variants, default workers)", batches))
        size = min(2500, max(1, n // 4))  # at least 4 batches, so that 2 workers share them
        scaling = [run(n, size, 1, threads=1), run(n, size, 1), run(n, size, 2)]
        sections.append((f"Rate against workers ({n:,} variants, batch {size:,})", scaling))
        if args.full:
            sections.append(("Peak memory against sweep size (batch 2,500, default workers)",
                             [run(10_000, 2500, 0), run(100_000, 2500, 0)]))  # fmt: skip
    if args.json:
        print(json.dumps({"machine": info, "tables": dict(sections)}, indent=2))
        return
    print(f"vrusim sweep {SPEC.relative_to(ROOT)} (python -m vrusim, one process per row)\n{header(info)}")
    for title, rows in sections:
        print(f"\n{title}\n\n{table(rows)}")
        if args.goal is not None:
            print("\n" + "\n".join(goal_verdict(row) for row in rows))
        elif title.startswith("Rate against workers"):
            efficiency = rows[2]["wall_variants_per_s"] / (2 * rows[0]["wall_variants_per_s"])
            print(f"\nscaling efficiency (wall), 2 workers vs 1 core: {efficiency:.0%}")


if __name__ == "__main__":
    main()
