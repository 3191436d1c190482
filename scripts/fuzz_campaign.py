"""Fuzz campaign (issue 18), run outside CI: thousands of malformed scenario files, sweep specs and command lines.

    python scripts/fuzz_campaign.py                      # 1,200 inputs of each of 5 kinds: 6,000 in all
    python scripts/fuzz_campaign.py --examples 200 --kinds cli --json

The generators are the suite's (`tests/fuzz_inputs.py`; `tests/test_fuzz.py` runs a fixed few in CI). Each kind
runs in a child process of its own, one input after the other, in-process through Typer's runner: per input the
exit code, whether a traceback escaped, and the wall time (an alarm stops an input after `--timeout` s, counted
as a hang). Per child the peak resident memory. Pass: 0 tracebacks, 0 hangs, every child's peak under
`--max-memory-mb`; the exit code says so (0 pass, 1 fail). Inputs that failed are listed with their arguments.
"""

from __future__ import annotations

import argparse
import json
import resource
import signal
import subprocess
import sys
import tempfile
import time
from collections import Counter
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
KINDS = ("scenario", "physics", "xosc", "sweep", "cli")


class HangError(Exception):
    """An input ran past the timeout."""


def _alarm(signum: int, frame: object) -> None:
    raise HangError


def child(kind: str, examples: int, timeout_s: float, seed: int) -> dict:
    """Run `examples` inputs of one kind in this process; the counts, the slowest input and the peak memory."""
    sys.path.insert(0, str(ROOT / "tests"))
    from hypothesis import HealthCheck, given, settings
    from hypothesis import seed as hypothesis_seed

    from fuzz_inputs import (
        cli_arguments,
        finite_results,
        invoke_cli,
        physics_texts,
        scenario_texts,
        sweep_texts,
        with_folder,
        write_input,
        xosc_texts,
    )

    counts: Counter = Counter()
    failures: list[dict] = []
    slowest = [0.0, None]
    signal.signal(signal.SIGALRM, _alarm)

    def one(args: list[str], text: str | None) -> None:
        with tempfile.TemporaryDirectory() as folder:
            if text is not None:
                path = write_input(Path(folder), text, ".xosc" if kind == "xosc" else ".yaml")
                args = [arg.replace("{file}", str(path)) for arg in args]
            args = with_folder(args, folder)
            started = time.perf_counter()
            signal.setitimer(signal.ITIMER_REAL, timeout_s)
            try:
                verdict = invoke_cli(args)
                hang = False
            except HangError:
                verdict, hang = None, True
            finally:
                signal.setitimer(signal.ITIMER_REAL, 0)
            elapsed = time.perf_counter() - started
        if elapsed > slowest[0]:
            slowest[:] = [round(elapsed, 3), [a[:80] for a in args]]
        counts["inputs"] += 1
        if hang or elapsed > timeout_s:
            counts["hangs"] += 1
            failures.append({"why": "hang", "seconds": round(elapsed, 2), "args": [a[:200] for a in args]})
            return
        counts[f"exit {verdict.exit_code}"] += 1
        if verdict.traceback is not None or "Traceback" in verdict.output:
            counts["tracebacks"] += 1
            last = (verdict.traceback or verdict.output).strip().splitlines()[-1]
            failures.append({"why": last[:300], "args": [a[:200] for a in args]})
        elif not verdict.acceptable:
            counts["unclear"] += 1
            failures.append({"why": f"exit {verdict.exit_code}: {verdict.output[-300:]}", "args": args[:3]})
        elif verdict.exit_code == 0 and not finite_results(verdict.output):
            counts["non-finite results"] += 1
            failures.append({"why": "NaN or infinity in the results", "args": args[:3]})

    common = settings(
        max_examples=examples,
        deadline=None,
        database=None,
        suppress_health_check=list(HealthCheck),
    )
    if kind == "cli":

        @hypothesis_seed(seed)
        @common
        @given(args=cli_arguments())
        def run(args):
            one(args, None)

    else:
        texts = {"scenario": scenario_texts, "physics": physics_texts, "xosc": xosc_texts, "sweep": sweep_texts}[kind]()
        command = ["sweep", "{file}", "--dry-run", "--json"] if kind == "sweep" else ["run", "{file}", "--json"]

        @hypothesis_seed(seed)
        @common
        @given(text=texts)
        def run(text):
            one(list(command), text)

    run()
    peak_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    return {"kind": kind, "counts": dict(counts), "peak_rss_mb": round(peak_mb, 1), "slowest": slowest,
            "failures": failures}  # fmt: skip


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--examples", type=int, default=1200, help="inputs per kind (default 1200)")
    parser.add_argument("--kinds", default=",".join(KINDS), help="comma-separated: " + ", ".join(KINDS))
    parser.add_argument("--timeout", type=float, default=20.0, help="seconds before an input counts as a hang")
    parser.add_argument("--max-memory-mb", type=float, default=1024.0, help="peak memory allowed per child, MB")
    parser.add_argument("--seed", type=int, default=2026, help="hypothesis seed (a campaign is reproducible)")
    parser.add_argument("--json", action="store_true", help="print the whole report as JSON")
    parser.add_argument("--child", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        print(json.dumps(child(args.child, args.examples, args.timeout, args.seed)))
        return 0
    started = time.perf_counter()
    reports = []
    for kind in [k.strip() for k in args.kinds.split(",") if k.strip()]:
        if kind not in KINDS:
            parser.error(f"--kinds: unknown kind {kind!r}; expected {', '.join(KINDS)}")
        done = subprocess.run(
            [sys.executable, __file__, "--child", kind, "--examples", str(args.examples),
             "--timeout", str(args.timeout), "--seed", str(args.seed)],
            capture_output=True, text=True, check=False,
        )  # fmt: skip
        if done.returncode != 0:
            reports.append(
                {"kind": kind, "counts": {"crashed": 1}, "peak_rss_mb": None, "failures": [done.stderr[-2000:]]}
            )
            continue
        reports.append(json.loads(done.stdout.strip().splitlines()[-1]))
    total: Counter = Counter()
    for report in reports:
        total.update(report["counts"])
    peak = max((r["peak_rss_mb"] or 0.0) for r in reports)
    failed = ("tracebacks", "hangs", "crashed", "unclear", "non-finite results")
    passed = not any(total[name] for name in failed) and peak <= args.max_memory_mb
    summary = {"total": dict(total), "peak_rss_mb": peak, "wall_s": round(time.perf_counter() - started, 1),
               "passed": passed, "kinds": reports}  # fmt: skip
    if args.json:
        print(json.dumps(summary, indent=2))
    else:
        for report in reports:
            peak_mb, slowest = report["peak_rss_mb"], report.get("slowest")
            print(f"{report['kind']:9} {report['counts']}  peak {peak_mb} MB  slowest {slowest}")
            for failure in report["failures"][:20]:
                print("   ", failure)
        print(f"total {dict(total)}; peak RSS {peak} MB; {summary['wall_s']} s; {'PASS' if passed else 'FAIL'}")
    return 0 if passed else 1


if __name__ == "__main__":
    sys.exit(main())
