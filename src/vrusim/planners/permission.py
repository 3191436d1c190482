"""Whether `module:Class` planner names may import their module: the switch, by environment variable or option.

Kept apart from the planner registry (and free of imports) so that the command line can declare its option
without importing the planners and their compiled kernels.
"""

from __future__ import annotations

import os

MODULE_PLANNERS_ENV = "VRUSIM_ALLOW_MODULE_PLANNERS"
"""Set to 1 (or true / yes) to let `planner.name: module:Class` import its module."""
MODULE_PLANNERS_FLAG = "--allow-module-planners"
"""The `vrusim` option that sets MODULE_PLANNERS_ENV for the command (and the workers it starts)."""


def module_planners_allowed() -> bool:
    """Whether `module:Class` planner names may be imported (MODULE_PLANNERS_ENV is 1, true or yes)."""
    return os.environ.get(MODULE_PLANNERS_ENV, "").strip().lower() in ("1", "true", "yes")


def allow_module_planners(allowed: bool = True) -> None:
    """Allow (or forbid again) `module:Class` planner names in this process and the worker processes it starts."""
    if allowed:
        os.environ[MODULE_PLANNERS_ENV] = "1"
    else:
        os.environ.pop(MODULE_PLANNERS_ENV, None)
