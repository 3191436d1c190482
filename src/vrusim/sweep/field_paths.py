"""Dotted field paths as a sweep spec uses them (`set` and `parameters`): the scenario's paths, with sweep hints.

The paths themselves (parsing, checking, copy-on-write variants) live in `vrusim.scenario.field_paths`; a
sweep only adds that a field not set in the base scenario can be given a value under `set`.
"""

from __future__ import annotations

from pydantic import BaseModel

from vrusim.scenario import field_paths
from vrusim.scenario.field_paths import Step, parse_path, with_values

__all__ = ["Step", "check_path", "parse_path", "with_values"]

SWEEP_UNSET_HINT = "give it a value there (or under `set`) first"


def check_path(base: BaseModel, path: str, where: str = "parameters") -> tuple[Step, ...]:
    """The parsed path if it names a field of `base`; otherwise a UserInputError naming `where` and the step."""
    return field_paths.check_path(base, path, where, SWEEP_UNSET_HINT)
