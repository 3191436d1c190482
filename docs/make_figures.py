"""Draw the README figures: the paper's six runs over time, and the FSM planner's Euro NCAP scorecard.

Run: python docs/make_figures.py   (writes docs/img/paper_timelines.png, docs/img/ncap_scorecard_fsm.png and
docs/img/ncap2026_scorecard_aeb.png)
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from vrusim.engine.simulate import simulate
from vrusim.metrics.summary import summary_rows
from vrusim.paper.cases import CASES, paper_scenarios

OUT = Path(__file__).parent / "img" / "paper_timelines.png"
SCORECARD = Path(__file__).parent / "img" / "ncap_scorecard_fsm.png"
SCORECARD_2026 = Path(__file__).parent / "img" / "ncap2026_scorecard_aeb.png"
MODE_COLOURS = {"cruise": "#e8f1e8", "pre_slow": "#fff2c6", "emergency_brake": "#f8d0d0", "follow": "#dbe7f7"}


def main() -> None:
    runs = paper_scenarios()
    run = simulate([scenario for _, _, scenario in runs], trace=True)
    rows = summary_rows(run)
    trace = run.trace
    fig, axes = plt.subplots(2, len(CASES), figsize=(13, 5.2), sharex="col", constrained_layout=True)
    for b, ((case, v2x, _), row) in enumerate(zip(runs, rows, strict=True)):
        ax = axes[int(v2x), [c.key for c in CASES].index(case.key)]
        end = row["end_time_s"]
        t = trace["t_s"]
        keep = t <= end + 1e-9
        mode = trace["planner_mode"][keep, b]
        for start, stop, value in _spans(t[keep], mode):
            ax.axvspan(start, stop, color=MODE_COLOURS[run.mode_names[value]], lw=0)
        ax.plot(t[keep], trace["ego_speed_mps"][keep, b], color="black", lw=1.6, label="ego speed")
        ax.plot(t[keep], trace["vru_speed_mps"][keep, b, 0], color="tab:blue", lw=1.2, ls="--", label="VRU speed")
        for key, colour, label in (
            ("first_sensor_detection_s", "tab:green", "sensor"),
            ("first_v2x_message_s", "tab:purple", "V2X"),
            ("contact_time_s", "tab:red", "impact"),
        ):
            if row[key] is not None:
                ax.axvline(row[key], color=colour, lw=1.2)
                ax.text(
                    row[key],
                    ax.get_ylim()[1] * 0.02 + 0.3,
                    f" {label} {row[key]:.2f} s",
                    color=colour,
                    fontsize=7,
                    rotation=90,
                    va="bottom",
                )
        scores = f"S/E/C {row['safety']:.2f}/{row['efficiency']:.2f}/{row['comfort']:.2f}"
        ax.set_title(f"{case.title} — V2X {'on' if v2x else 'off'}\n{row['outcome']}, {scores}", fontsize=9)
        ax.set_xlim(0, max(end, 1.0))
        ax.set_ylim(bottom=0)
        ax.grid(alpha=0.3)
        if v2x:
            ax.set_xlabel("time (s)")
        if case.key == CASES[0].key:
            ax.set_ylabel("speed (m/s)")
    handles = [plt.Rectangle((0, 0), 1, 1, color=c) for c in MODE_COLOURS.values()]
    fig.legend(
        handles + axes[0, 0].get_lines()[:2],
        [*MODE_COLOURS, "ego speed", "VRU speed"],
        loc="outside lower center",
        ncol=6,
        fontsize=8,
    )
    OUT.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(OUT, dpi=110)
    print(f"wrote {OUT}")


def _spans(t: np.ndarray, mode: np.ndarray):
    """(start, stop, mode) of each run of equal planner modes."""
    change = np.flatnonzero(np.diff(mode)) + 1
    starts = np.concatenate([[0], change])
    stops = np.concatenate([change, [len(mode)]])
    for a, b in zip(starts, stops, strict=True):
        yield t[a] - (t[1] - t[0]), t[b - 1], int(mode[a])


def scorecard() -> None:
    """The whole catalogue, day and night, FSM planner without V2X: `vrusim ncap --night --out DIR`."""
    from vrusim.ncap.assess import assess
    from vrusim.ncap.grid import run_tests, select
    from vrusim.viz.scorecard import write_scorecard_png

    assessment = assess(run_tests(select(night=True, protocol="2023"), planner="fsm", v2x=False).rows)
    write_scorecard_png(assessment, SCORECARD, dpi=80)


def scorecard_2026() -> None:
    """The whole 2026 grid, day and night, AEB planner without V2X: `vrusim ncap --planner aeb --night --out DIR`."""
    from vrusim.ncap.grid import select
    from vrusim.ncap.rated2026 import rate_2026
    from vrusim.viz.scorecard2026 import write_scorecard_2026_png

    rated = rate_2026(select(night=True, protocol="2026"), planner="aeb", v2x=False)
    write_scorecard_2026_png(rated.assessment, SCORECARD_2026, dpi=60)


if __name__ == "__main__":
    main()
    scorecard()
    scorecard_2026()
