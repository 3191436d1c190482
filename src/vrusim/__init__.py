"""vrusim: closed-loop simulation of vulnerable-road-user safety tests.

The public Python API (docs/api.md) is imported on first use, so `import vrusim` stays cheap and has no side
effects (no environment change, nothing written):

    import vrusim
    results = vrusim.run(vrusim.load("paper:pedestrian"))
    print(results.to_pandas())
"""

from __future__ import annotations

import typing as _typing

from vrusim.version import __version__

if _typing.TYPE_CHECKING:
    from vrusim.api import (
        CompileReport,
        NcapResults,
        NcapResults2026,
        Results,
        SweepFolder,
        compile_kernels,
        euro_ncap,
        load,
        open_sweep,
        run,
        run_sweep,
    )
    from vrusim.errors import UserInputError
    from vrusim.metrics.catalog import Metric, register_metric, unregister_metric
    from vrusim.scenario.schema import Scenario
    from vrusim.sim.v2x.loss.registry import register_loss_model, unregister_loss_model
    from vrusim.sim.vru.registry import register_vru_motion, unregister_vru_motion

__all__ = [
    "CompileReport",
    "Metric",
    "NcapResults",
    "NcapResults2026",
    "Results",
    "Scenario",
    "SweepFolder",
    "UserInputError",
    "__version__",
    "compile_kernels",
    "euro_ncap",
    "load",
    "open_sweep",
    "register_loss_model",
    "register_metric",
    "register_vru_motion",
    "run",
    "run_sweep",
    "unregister_loss_model",
    "unregister_metric",
    "unregister_vru_motion",
]

_HOME = {
    "Scenario": "vrusim.scenario.schema",
    "UserInputError": "vrusim.errors",
    "Metric": "vrusim.metrics.catalog",
    "register_metric": "vrusim.metrics.catalog",
    "unregister_metric": "vrusim.metrics.catalog",
    "register_loss_model": "vrusim.sim.v2x.loss.registry",
    "unregister_loss_model": "vrusim.sim.v2x.loss.registry",
    "register_vru_motion": "vrusim.sim.vru.registry",
    "unregister_vru_motion": "vrusim.sim.vru.registry",
}
"""Where the public names that are not the API's own live (every other one: vrusim.api)."""


def __getattr__(name: str) -> _typing.Any:
    """Import a public name on first use (PEP 562) and keep it, so later look-ups are plain attributes."""
    if name not in __all__:
        raise AttributeError(f"module 'vrusim' has no attribute {name!r}")
    import importlib

    value = getattr(importlib.import_module(_HOME.get(name, "vrusim.api")), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    """The public names (what `from vrusim import *` gives)."""
    return sorted(__all__)
