"""Sweep throughput end to end (planning, simulation, Parquet storage) and peak memory, on the pedestrian
Monte Carlo of `sweeps/pedestrian_monte_carlo.yaml` (V2X on with uncertain latency and loss).

Run: python benchmarks/bench_sweep.py [--variants 10000] [--full]

Each configuration runs `vrusim sweep` in its own process; the rate is variants / wall time of the whole
command's sweep (as it reports), the memory the peak resident set of the command plus its worker processes,
sampled every 50 ms. Tables: rate against batch size (2 workers), against workers (1 core, 1 process with
all cores as threads, 2 processes; scaling efficiency = rate / (workers × 1-core rate)), and peak memory for
10^4 and 10^5 variants (`--full`; the 10^5 sweep is the issue's 100,000-variant Monte Carlo).
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

ROOT = Path(__file__).resolve().parents[1]
SPEC = ROOT / "sweeps" / "pedestrian_monte_carlo.yaml"


def _tree_rss(process: psutil.Process) -> int:
    total = 0
    with contextlib.suppress(psutil.Error):  # the command or a worker that just ended
        for member in [process, *process.children(recursive=True)]:
            with contextlib.suppress(psutil.Error):
                total += member.memory_info().rss
    return total


def run(variants: int, batch_size: int, workers: int, threads: int | None = None) -> dict:
    """One sweep in a fresh process: reported rate and elapsed time, peak memory of the process tree."""
    data = yaml.safe_load(SPEC.read_text())
    data.update(samples=variants, batch_size=batch_size, base=str(ROOT / "scenarios/paper/pedestrian_crossing.yaml"))
    with tempfile.TemporaryDirectory() as folder:
        spec = Path(folder) / "spec.yaml"
        spec.write_text(yaml.safe_dump(data))
        env = dict(os.environ)
        if threads is not None:
            env["NUMBA_NUM_THREADS"] = str(threads)
        command = [sys.executable, "-m", "vrusim", "sweep", str(spec), "--out", f"{folder}/out"]
        command += ["--workers", str(workers), "--json"]
        started = time.perf_counter()
        child = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
        peak = 0
        watcher = psutil.Process(child.pid)

        def sample() -> None:
            nonlocal peak
            while child.poll() is None:
                peak = max(peak, _tree_rss(watcher))
                time.sleep(0.05)

        thread = threading.Thread(target=sample)
        thread.start()
        stdout, stderr = child.communicate()
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
        "sweep_s": outcome["elapsed_s"],
        "command_s": round(time.perf_counter() - started, 2),
        "variants_per_s": outcome["variants_per_s"],
        "peak_rss_mb": round(peak / 1e6),
        "stored_mb": round(stored_mb, 1),
    }


def _print(title: str, rows: list[dict]) -> None:
    print(f"\n{title}")
    print(f"{'variants':>9} {'batch':>6} {'workers':>8} {'threads':>8} {'sweep s':>8} {'variants/s':>11} "
          f"{'peak RSS MB':>12} {'Parquet MB':>11}")  # fmt: skip
    for r in rows:
        setting = f"{r['variants']:>9} {r['batch_size']:>6} {r['workers']:>8} {r['threads'] or 'all':>8}"
        measured = f"{r['sweep_s']:>8.1f} {r['variants_per_s']:>11,.0f} {r['peak_rss_mb']:>12} {r['stored_mb']:>11}"
        print(f"{setting} {measured}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--variants", type=int, default=10_000, help="variants of the batch and worker tables")
    parser.add_argument("--full", action="store_true", help="also the 10^4 / 10^5 memory table (minutes)")
    parser.add_argument("--json", action="store_true", help="print every row as JSON too")
    args = parser.parse_args()
    n = args.variants
    run(500, 250, 1)  # warm-up: the compiled-kernel cache
    batches = [run(n, size, 2) for size in (250, 1000, 2500, 5000)]
    _print(f"Rate against batch size ({n:,} variants, 2 workers)", batches)
    one_core = run(n, 2500, 1, threads=1)
    scaling = [one_core, run(n, 2500, 1), run(n, 2500, 2)]
    _print(f"Rate against workers ({n:,} variants, batch 2500)", scaling)
    base = one_core["variants_per_s"]
    print(f"scaling efficiency, 2 workers vs 1 core: {scaling[2]['variants_per_s'] / (2 * base):.0%}")
    rows = batches + scaling
    if args.full:
        memory = [run(10_000, 2500, 2), run(100_000, 2500, 2)]
        _print("Peak memory against sweep size (batch 2500, 2 workers)", memory)
        rows += memory
    if args.json:
        print(json.dumps(rows, indent=2))


if __name__ == "__main__":
    main()
