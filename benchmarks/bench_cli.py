"""Wall time of whole `vrusim` commands, process start included (issue 20): `vrusim ncap` on the 2026 grid, a warm
`vrusim run` on each paper case, and a cold start that compiles the kernels.

Run: python benchmarks/bench_cli.py [--runs 5] [--parts ncap run cold] [--installed] [--json]

- ncap: `vrusim ncap --night --protocol 2026 --planner fsm` (the whole 2026 grid, day and night, 636 tests);
  goal < 1.5 s wall.
- run: `vrusim run scenarios/paper/<case>.yaml` for each paper case (as the file has it: FSM, V2X off); goal
  < 1 s wall.
- cold: the first `vrusim run` on the pedestrian case with `NUMBA_CACHE_DIR` set to a fresh empty folder, so
  every kernel it uses compiles; its wall time, and whether its stderr says so (mentions "compil"; the goal: the
  first run after install tells the user that kernels are compiling).

Each warm command runs once unmeasured (filling the compiled-kernel cache and Python's bytecode cache), then `--runs`
times; the table gives the fastest and the median wall time, from starting the process to its exit, terminal output
discarded. Commands run as `python -m vrusim` with this Python (the code on PYTHONPATH, e.g. a worktree's src);
`--installed` runs the `vrusim` console script next to this Python instead. Warm commands run without
PYTHONDONTWRITEBYTECODE (set in some sandboxes and CI images): with it Python recompiles every vrusim module from
source at each start (about 0.13 s on this VM), which no installed copy does after its first run.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from machine import header, machine, markdown_table

ROOT = Path(__file__).resolve().parents[1]
PAPER = sorted((ROOT / "scenarios" / "paper").glob("*.yaml"))
NCAP_GOAL_S, RUN_GOAL_S = 1.5, 1.0
NCAP = ["ncap", "--night", "--protocol", "2026", "--planner", "fsm"]
WARM_ENV = {name: value for name, value in os.environ.items() if name != "PYTHONDONTWRITEBYTECODE"}
"""The environment of warm commands: Python may keep its bytecode cache (see the module docstring)."""


def vrusim(installed: bool) -> list[str]:
    """The command that starts vrusim."""
    return [str(Path(sys.executable).with_name("vrusim"))] if installed else [sys.executable, "-m", "vrusim"]


def wall(command: list[str], env: dict[str, str] | None = None) -> tuple[float, str]:
    """Wall seconds of one process from start to exit (stdout discarded), and its stderr."""
    started = time.perf_counter()
    done = subprocess.run(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, env=env)
    seconds = time.perf_counter() - started
    if done.returncode != 0:
        raise SystemExit(f"{' '.join(command)} failed ({done.returncode}):\n{done.stderr}")
    return seconds, done.stderr


def warm(name: str, command: list[str], runs: int, goal_s: float) -> dict:
    """One unmeasured run, then `runs` measured ones: fastest and median wall time against the goal."""
    wall(command, WARM_ENV)
    times = [wall(command, WARM_ENV)[0] for _ in range(runs)]
    return {
        "command": name,
        "runs": runs,
        "min_s": round(min(times), 3),
        "median_s": round(statistics.median(times), 3),
        "goal_s": goal_s,
        "met": statistics.median(times) < goal_s,
    }


def cold(start: list[str], case: Path) -> dict:
    """The first `vrusim run` with an empty kernel cache: wall time and whether stderr mentions compiling."""
    with tempfile.TemporaryDirectory(prefix="vrusim-cold-") as cache:
        env = {**os.environ, "NUMBA_CACHE_DIR": cache}
        seconds, stderr = wall([*start, "run", str(case)], env)
    lines = [line.strip() for line in stderr.splitlines() if "compil" in line.lower()]
    return {
        "command": f"vrusim run {case.relative_to(ROOT)} (empty NUMBA_CACHE_DIR)",
        "wall_s": round(seconds, 2),
        "says_compiling": bool(lines),
        "stderr_line": lines[0] if lines else "",
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--runs", type=int, default=5, help="measured runs of each warm command")
    parser.add_argument("--parts", nargs="+", default=["ncap", "run", "cold"], choices=["ncap", "run", "cold"])
    parser.add_argument("--installed", action="store_true", help="run the installed `vrusim` console script")
    parser.add_argument("--json", action="store_true", help="print the rows and the machine as JSON, not tables")
    args = parser.parse_args()
    info = machine()
    start = vrusim(args.installed)
    rows: list[dict] = []
    if "ncap" in args.parts:
        rows.append(warm("vrusim " + " ".join(NCAP), [*start, *NCAP], args.runs, NCAP_GOAL_S))
    if "run" in args.parts:
        for case in PAPER:
            name = f"vrusim run {case.relative_to(ROOT)}"
            rows.append(warm(name, [*start, "run", str(case)], args.runs, RUN_GOAL_S))
    cold_row = cold(start, ROOT / "scenarios" / "paper" / "pedestrian_crossing.yaml") if "cold" in args.parts else None
    if args.json:
        print(json.dumps({"machine": info, "warm": rows, "cold": cold_row}, indent=2))
        return
    print(f"Whole vrusim commands, wall time with process start ({' '.join(start)})\n{header(info)}")
    if rows:
        cells = [
            [
                f"`{r['command']}`",
                r["runs"],
                f"{r['min_s']:.2f}",
                f"{r['median_s']:.2f}",
                f"< {r['goal_s']:g} s: {'met' if r['met'] else 'not met'}",
            ]
            for r in rows
        ]
        columns = ["command (warm kernel cache)", "runs", "fastest s", "median s", "goal (median)"]
        print(f"\n{markdown_table(columns, cells)}")
    if cold_row is not None:
        said = f"yes: {cold_row['stderr_line']!r}" if cold_row["says_compiling"] else "no"
        cells = [[f"`{cold_row['command']}`", f"{cold_row['wall_s']:.1f}", said]]
        print(f"\n{markdown_table(['cold start', 'wall s', 'stderr mentions compiling'], cells, right={1})}")


if __name__ == "__main__":
    main()
