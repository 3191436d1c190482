"""Draw the figure of an imported road in docs/openscenario_import.md: the T junction of the drawn-road tests
(`tests/data/xosc/roads/junction.xosc` and its `.xodr`) imported, run (planner none) and drawn at t = 2 s.

Run: python docs/road_figure.py   (writes docs/img/imported_t_junction.png)
"""

from __future__ import annotations

from pathlib import Path

from vrusim.formats.xosc_import import read_xosc
from vrusim.scenario.settings import with_settings
from vrusim.viz.recording import record
from vrusim.viz.scene import ViewWindow, scene_figure

ROOT = Path(__file__).resolve().parents[1]
SOURCE = ROOT / "tests" / "data" / "xosc" / "roads" / "junction.xosc"
OUT = Path(__file__).parent / "img" / "imported_t_junction.png"
WINDOW = ViewWindow((-42.0, 42.0, -24.0, 8.0), 84.0, 32.0, follow=False)
"""The junction and the arms around it, m."""


def main() -> None:
    scenario = with_settings(read_xosc(SOURCE), planner="none")
    recording = record([scenario])[0]
    figure = scene_figure(recording, 2.0, width_in=8.0, dpi=80.0, window=WINDOW)
    figure.savefig(OUT)
    print(f"wrote {OUT} ({OUT.stat().st_size / 1000:.0f} kB)")


if __name__ == "__main__":
    main()
