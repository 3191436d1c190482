"""Rendering cost of the figures and animations of the paper's case studies.

Run: python benchmarks/bench_render.py [--fps 25] [--cases escooter,pedestrian,motorcyclist] [--json]

Per case: the snapshot PNG (rows V2X off / on, at the key moments) and the time-series PNG at the
`paper --figures` resolution; per run (V2X off and on): GIF and MP4 at `fps` frames per second of simulated
time, 800 px wide (the `vrusim run --animate` defaults). Wall-clock seconds, written to a temporary folder,
after a warm-up. The goal: an animation of a 10 s run written in under 20 s on 2 cores.
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from pathlib import Path


def _timed(action) -> float:
    started = time.perf_counter()
    action()
    return time.perf_counter() - started


def measure(cases: list[str], fps: float) -> list[dict]:
    """One row per (case, output): seconds, simulated duration and frame count where it applies."""
    from vrusim.cli.figures import PAPER_FIGURE_DPI
    from vrusim.paper.cases import paper_scenarios
    from vrusim.viz.animate import frame_times, write_animation
    from vrusim.viz.figure_io import write_figure
    from vrusim.viz.recording import record
    from vrusim.viz.snapshots import snapshot_figure
    from vrusim.viz.timeseries import timeseries_figure

    runs = [(case, v2x, s) for case, v2x, s in paper_scenarios() if case.key in cases]
    recordings = record([s for _, _, s in runs])
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        out = Path(folder)
        write_animation(recordings[0], out / "warm.gif", fps=5, width_in=2, dpi=50)  # fonts, caches
        for key in cases:
            pair = [rec for (case, _, _), rec in zip(runs, recordings, strict=True) if case.key == key]
            for kind, build in (("snapshot PNG", snapshot_figure), ("time-series PNG", timeseries_figure)):
                seconds = _timed(lambda b=build, p=pair: write_figure(b(p), out / "f.png", PAPER_FIGURE_DPI))
                rows.append({"case": key, "v2x": "off+on", "output": kind, "seconds": seconds})
            for rec in pair:
                for suffix in (".gif", ".mp4"):
                    seconds = _timed(lambda r=rec, s=suffix: write_animation(r, out / f"a{s}", fps=fps))
                    rows.append(
                        {
                            "case": key,
                            "v2x": "on" if rec.scenario.v2x.enabled else "off",
                            "output": suffix[1:].upper(),
                            "run_s": round(float(rec.t_s[-1]), 2),
                            "frames": len(frame_times(rec, fps)),
                            "seconds": seconds,
                        }
                    )
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--fps", type=float, default=25.0)
    parser.add_argument("--cases", default="escooter,pedestrian,motorcyclist")
    parser.add_argument("--json", action="store_true", help="print the rows as JSON")
    args = parser.parse_args()
    rows = measure(args.cases.split(","), args.fps)
    if args.json:
        print(json.dumps(rows, indent=2))
        return
    print(f"{'case':<13}{'V2X':<8}{'output':<17}{'run (s)':>8}{'frames':>8}{'render (s)':>12}")
    for row in rows:
        run_s = f"{row['run_s']:.2f}" if "run_s" in row else ""
        frames = str(row.get("frames", ""))
        print(f"{row['case']:<13}{row['v2x']:<8}{row['output']:<17}{run_s:>8}{frames:>8}{row['seconds']:>12.2f}")


if __name__ == "__main__":
    main()
