"""V2X latency and loss sweeps on the paper's pedestrian case (FSM planner): table and figure for docs/v2x_study.md.

Run: python docs/v2x_study.py [--seeds 200]   (writes docs/img/v2x_sensitivity.png, prints the Markdown table)
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from vrusim.paper.cases import scenario_dir
from vrusim.scenario.loading import load_scenario
from vrusim.studies.v2x_sensitivity import MAX_BURSTY_LOSS, flip, onset, sweep

OUT = Path(__file__).parent / "img" / "v2x_sensitivity.png"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=200)
    args = parser.parse_args()
    base = load_scenario(scenario_dir() / "pedestrian_crossing.yaml")
    coarse = np.arange(0.0, 1.001, 0.05)
    latencies = sorted({round(x, 2) for x in np.concatenate([coarse, np.arange(0.8, 0.901, 0.01)])})
    losses = [round(x, 2) for x in np.arange(0.0, 0.901, 0.05)]
    sweeps = {
        "latency": sweep(base, "latency", latencies, 1),  # no loss, no jitter: deterministic
        "bernoulli": sweep(base, "bernoulli", losses, args.seeds),
        "bursty": sweep(base, "bursty", [x for x in losses if x <= MAX_BURSTY_LOSS], args.seeds),
    }
    print("| Sweep | Onset (first collision) | Flip (P ≥ 0.5) | P at the largest value |")
    print("|---|---|---|---|")
    for kind, points in sweeps.items():
        unit = " s" if kind == "latency" else ""
        first, half = onset(points), flip(points)
        last = points[-1]
        print(
            f"| {kind} | {'none' if first is None else f'{first:g}{unit}'} | "
            f"{'none' if half is None else f'{half:g}{unit}'} | {last.probability:.2f} at {last.value:g}{unit} |"
        )
    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 3.6), constrained_layout=True)
    lat = sweeps["latency"]
    left.step([p.value for p in lat], [p.probability for p in lat], where="post", color="black")
    left.set(xlabel="V2X latency (s), no loss", ylabel="collision probability", ylim=(-0.03, 1.03))
    for kind, colour in (("bernoulli", "tab:blue"), ("bursty", "tab:red")):
        points = sweeps[kind]
        x = [p.value for p in points]
        low, high = zip(*(p.interval for p in points), strict=True)
        right.plot(x, [p.probability for p in points], marker="o", ms=3, color=colour, label=kind)
        right.fill_between(x, low, high, color=colour, alpha=0.2)
    right.set(xlabel="packet loss (stationary), latency 0.1 s", ylim=(-0.03, 1.03))
    right.legend(title=f"{args.seeds} seeds, Wilson 95 %")
    fig.suptitle("Paper pedestrian case, FSM planner, V2X on: when does the outcome flip?")
    fig.savefig(OUT, dpi=100)
    print(f"wrote {OUT}")


if __name__ == "__main__":
    main()
