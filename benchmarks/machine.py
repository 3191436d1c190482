"""The date and machine a benchmark ran on, for the header of its table (the README quotes both).

CPU model and logical cores from /proc/cpuinfo and os (Linux; "unknown CPU" elsewhere), the Python, NumPy and
Numba versions, and the Numba thread count the benchmark's processes get (NUMBA_NUM_THREADS, default: all cores).
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import platform
from collections.abc import Callable
from pathlib import Path


def cpu_model() -> str:
    """The CPU's model name from /proc/cpuinfo ("unknown CPU" where there is none)."""
    try:
        text = Path("/proc/cpuinfo").read_text()
    except OSError:
        return platform.processor() or "unknown CPU"
    for line in text.splitlines():
        if line.startswith("model name"):
            return line.split(":", 1)[1].strip()
    return platform.processor() or "unknown CPU"


def machine() -> dict[str, str | int]:
    """Date (UTC, ISO), CPU model, logical cores, Python / NumPy / Numba versions and Numba threads."""
    import numba
    import numpy

    return {
        "date": datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%d %H:%M UTC"),
        "cpu": cpu_model(),
        "cores": os.cpu_count() or 1,
        "python": platform.python_version(),
        "numpy": numpy.__version__,
        "numba": numba.__version__,
        "numba_threads": os.environ.get("NUMBA_NUM_THREADS", "all"),
    }


def header(info: dict[str, str | int] | None = None) -> str:
    """One line: `2026-11-26 10:00 UTC · Intel Xeon … · 2 cores · Python 3.11.7, NumPy 2.4.0, Numba 0.68.0`."""
    m = info or machine()
    return (
        f"{m['date']} · {m['cpu']} · {m['cores']} cores · Python {m['python']}, NumPy {m['numpy']}, "
        f"Numba {m['numba']} (threads: {m['numba_threads']})"
    )


def markdown_table(columns: list[str], rows: list[list[str]], right: set[int] | None = None) -> str:
    """A markdown table; columns whose index is in `right` are right-aligned (numbers)."""
    right = right if right is not None else set(range(1, len(columns)))
    rule = ["---:" if j in right else "---" for j in range(len(columns))]
    lines = [columns, rule, *rows]
    return "\n".join("| " + " | ".join(str(cell) for cell in line) + " |" for line in lines)


def kernel_options(
    description: str, batch: int = 2000, repeats: int = 5, json_output: bool = True
) -> argparse.ArgumentParser:
    """The options of the kernel benchmarks: --batch (variants), --steps, --repeats (the best one counts) and, with
    `json_output`, --json (`run_kernel_benchmark`)."""
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("--batch", type=int, default=batch)
    parser.add_argument("--steps", type=int, default=1000)
    parser.add_argument("--repeats", type=int, default=repeats)
    if json_output:
        parser.add_argument("--json", action="store_true")
    return parser


def run_kernel_benchmark(
    description: str,
    measure: Callable[[int, int, int], list[dict]],
    title: str,
    columns: dict[str, Callable[[dict], str]],
) -> None:
    """A kernel benchmark's command: its options (`kernel_options`), `measure(batch, steps, repeats)`'s rows, and
    either those rows as JSON with the machine (--json) or the title, the machine's header and a table whose
    `columns` map each heading to the cell of a row."""
    args = kernel_options(description).parse_args()
    rows = measure(args.batch, args.steps, args.repeats)
    if args.json:
        print(json.dumps({"machine": machine(), "batch": args.batch, "steps": args.steps, "rows": rows}, indent=2))
        return
    print(f"{title}, B = {args.batch:,}, {args.steps:,} steps, best of {args.repeats}")
    print(header())
    print()
    print(markdown_table(list(columns), [[cell(row) for cell in columns.values()] for row in rows]))
