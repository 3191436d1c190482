"""Limits on what one input may ask of vrusim, checked before any work starts.

Each limit has a documented default (docs/limits.md) and an environment variable that changes it,
`VRUSIM_LIMIT_<NAME>` (e.g. `VRUSIM_LIMIT_INPUT_FILE_BYTES=20000000`). Exceeding one is a UserInputError that
names the field or option, the value and the limit, and says how to raise it.
"""

from __future__ import annotations

import os
from dataclasses import dataclass

from vrusim.errors import UserInputError


@dataclass(frozen=True)
class Limit:
    """One limit: its default, unit and what it bounds."""

    default: float
    unit: str
    bounds: str


LIMITS: dict[str, Limit] = {
    "input_file_bytes": Limit(2_000_000, "bytes", "size of a scenario, sweep spec or V2X channel YAML file"),
    "yaml_depth": Limit(32, "levels", "nesting of mappings and lists in a YAML file"),
    "yaml_nodes": Limit(200_000, "nodes", "values in a YAML file, counting every use of an alias (*anchor)"),
    "number_chars": Limit(64, "characters", "length of one number in a YAML file"),
    "list_items": Limit(100_000, "items", "items of one list in a YAML file"),
}
"""Every limit by name (the environment variable is VRUSIM_LIMIT_ + the name in capitals)."""


def env_name(name: str) -> str:
    """The environment variable that changes limit `name`."""
    return f"VRUSIM_LIMIT_{name.upper()}"


def limit(name: str) -> float:
    """The value of limit `name`: its environment variable if set (a positive number), else the default."""
    entry = LIMITS[name]
    text = os.environ.get(env_name(name))
    if text is None:
        return entry.default
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not value > 0 or value == float("inf"):
        raise UserInputError(f"{env_name(name)}: expected a positive number of {entry.unit}, got {text!r}")
    return value


def amount(value: float) -> str:
    """A count or size as text: whole numbers with thousands separators (2,000,000), others as %g."""
    return f"{int(value):,}" if float(value).is_integer() else f"{value:g}"


def check_limit(name: str, value: float, what: str) -> None:
    """Raise a UserInputError naming `what` if `value` exceeds limit `name`."""
    bound = limit(name)
    if value > bound:
        entry = LIMITS[name]
        raise UserInputError(
            f"{what}: {amount(value)} {entry.unit} exceeds the limit of {amount(bound)} ({entry.bounds}; "
            f"{env_name(name)} raises it)"
        )
