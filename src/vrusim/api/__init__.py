"""The public Python API, re-exported lazily by `vrusim` itself (`vrusim.load`, `vrusim.run`, ...).

    import vrusim
    results = vrusim.run(vrusim.load("paper:pedestrian"), v2x="on")
    results.to_pandas()

Reference: docs/api.md. Each name is imported from its module on first use (PEP 562), so that importing one
module of the package (`vrusim.api.settings` for the command line's checks) does not load the Euro NCAP and
sweep machinery.
"""

from __future__ import annotations

import typing as _typing

if _typing.TYPE_CHECKING:
    from vrusim.api.assessing import NcapResults, NcapResults2026, euro_ncap
    from vrusim.api.compiling import CompileReport, compile_kernels
    from vrusim.api.running import Results, load, run
    from vrusim.api.sweeping import SweepFolder, open_sweep, run_sweep

__all__ = [
    "CompileReport",
    "NcapResults",
    "NcapResults2026",
    "Results",
    "SweepFolder",
    "compile_kernels",
    "euro_ncap",
    "load",
    "open_sweep",
    "run",
    "run_sweep",
]

_HOME = {
    "CompileReport": "vrusim.api.compiling",
    "compile_kernels": "vrusim.api.compiling",
    "NcapResults": "vrusim.api.assessing",
    "NcapResults2026": "vrusim.api.assessing",
    "euro_ncap": "vrusim.api.assessing",
    "Results": "vrusim.api.running",
    "load": "vrusim.api.running",
    "run": "vrusim.api.running",
    "SweepFolder": "vrusim.api.sweeping",
    "open_sweep": "vrusim.api.sweeping",
    "run_sweep": "vrusim.api.sweeping",
}
"""The module each public name lives in."""


def __getattr__(name: str) -> _typing.Any:
    """Import a public name on first use and keep it, so later look-ups are plain attributes."""
    if name not in _HOME:
        raise AttributeError(f"module 'vrusim.api' has no attribute {name!r}")
    import importlib

    value = getattr(importlib.import_module(_HOME[name]), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    """The public names."""
    return sorted(__all__)
