"""OpenSCENARIO round trip over the whole Euro NCAP catalogue (issue 19), run outside CI.

    python scripts/xosc_round_trip.py            # the paper's cases and both editions (day and night), none and fsm

Every test is exported (`vrusim.interop.openscenario`), imported (`vrusim.formats.xosc_import`) and, with the
fields an export does not carry copied back from the original (`tests/test_xosc_import.py`), run next to the
original as one batch per planner. A test passes when the outcome and impact side are the same, the first
contact within 0.01 s and the impact point within 0.02 m. The suite checks a sample of the same
(`tests/test_xosc_import.py`); this script checks every test and prints the counts and the largest deviations.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CONTACT_S, POINT_M = 0.01, 0.02


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--protocols", default="2023,2026")
    parser.add_argument("--planners", default="none,fsm")
    args = parser.parse_args()
    sys.path.insert(0, str(ROOT / "tests"))
    from test_xosc_import import _with_unexported
    from vrusim.engine.simulate import simulate
    from vrusim.formats.xosc_import import read_xosc
    from vrusim.interop.openscenario import export_openscenario
    from vrusim.metrics.summary import summary_rows
    from vrusim.ncap.build import build_test
    from vrusim.ncap.grid import select
    from vrusim.paper.cases import scenario_dir
    from vrusim.scenario.loading import load_scenario
    from vrusim.scenario.settings import with_settings

    started = time.perf_counter()
    originals, imported = [], []
    paper = [load_scenario(path) for path in sorted(scenario_dir().glob("*.yaml"))]
    catalogue = [build_test(t).scenario for p in args.protocols.split(",") for t in select(night=True, protocol=p)]
    with tempfile.TemporaryDirectory() as folder:
        for scenario in paper + catalogue:
            export_openscenario(scenario, Path(folder), "case")
            originals.append(scenario)
            imported.append(_with_unexported(scenario, read_xosc(Path(folder) / "case.xosc")))
    converted_s = time.perf_counter() - started
    failures, worst = [], {"contact_s": 0.0, "point_m": 0.0}
    for planner in args.planners.split(","):
        before = summary_rows(simulate([with_settings(s, planner=planner) for s in originals]))
        after = summary_rows(simulate([with_settings(s, planner=planner) for s in imported]))
        for scenario, a, b in zip(originals, before, after, strict=True):
            same = a["outcome"] == b["outcome"] and a["impact_side"] == b["impact_side"]
            if same and a["contact_time_s"] is not None:
                worst["contact_s"] = max(worst["contact_s"], abs(a["contact_time_s"] - b["contact_time_s"]))
                point = max(abs(a[k] - b[k]) for k in ("impact_point_x_m", "impact_point_y_m"))
                worst["point_m"] = max(worst["point_m"], point)
                same = abs(a["contact_time_s"] - b["contact_time_s"]) <= CONTACT_S and point <= POINT_M
            if not same:
                failures.append(
                    (planner, scenario.name, a["outcome"], b["outcome"], a["contact_time_s"], b["contact_time_s"])
                )
    runs = len(originals) * len(args.planners.split(","))
    print(f"{len(paper)} paper cases and {len(catalogue)} catalogue tests exported and imported in "
          f"{converted_s:.1f} s; {runs} runs compared; {runs - len(failures)} match, {len(failures)} differ; "
          f"largest contact-time difference {worst['contact_s']:.4f} s, "
          f"impact point {worst['point_m']:.4f} m")  # fmt: skip
    for failure in failures[:40]:
        print("  differs:", failure)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
