"""The public Python API, re-exported lazily by `vrusim` itself (`vrusim.load`, `vrusim.run`, ...).

    import vrusim
    results = vrusim.run(vrusim.load("paper:pedestrian"), v2x="on")
    results.to_pandas()

Reference: docs/api.md.
"""

from __future__ import annotations

from vrusim.api.assessing import NcapResults, NcapResults2026, euro_ncap
from vrusim.api.running import Results, load, run
from vrusim.api.sweeping import SweepFolder, open_sweep, run_sweep

__all__ = [
    "NcapResults",
    "NcapResults2026",
    "Results",
    "SweepFolder",
    "euro_ncap",
    "load",
    "open_sweep",
    "run",
    "run_sweep",
]
