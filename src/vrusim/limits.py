"""Limits on what one input may ask of vrusim, checked before any work starts.

Each limit has a documented default (docs/limits.md) and an environment variable that changes it,
`VRUSIM_LIMIT_<NAME>` (e.g. `VRUSIM_LIMIT_INPUT_FILE_BYTES=20000000`). Exceeding one is a UserInputError that
names the field or option, the value and the limit, and says how to raise it.
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar
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
    "xml_number": Limit(1e10, "", "magnitude of a number in an OpenSCENARIO or OpenDRIVE attribute"),
    # physical bounds on scenario fields (vrusim.scenario.bounds), by the unit in the field's name
    "coordinate_m": Limit(100_000, "m", "|x| or |y| of a position, a field x_m or y_m"),
    "length_m": Limit(100_000, "m", "a length or distance, a field ending in _m, or a VRU path's total length"),
    "speed_mps": Limit(150, "m/s", "a speed, a field ending in _mps"),
    "accel_mps2": Limit(10_000, "m/s^2", "an acceleration, a field ending in _mps2"),
    # work budgets, checked before the work starts
    "sweep_variants": Limit(10_000_000, "variants", "variants of one sweep (grid points x samples)"),
    "distribution_variants": Limit(
        10_000, "variants", "variants of an OpenSCENARIO parameter distribution, each a whole scenario import"
    ),
    "compare_runs": Limit(100_000, "runs", "runs of one comparison (planners x V2X settings x seeds)"),
    "batch_variant_steps": Limit(10_000_000_000, "variant-steps", "variants x time steps of one batch run"),
    "trace_bytes": Limit(2_000_000_000, "bytes", "estimated memory of a run's trace (--trace, trace=True)"),
    "animation_frames": Limit(1_500, "frames", "frames of one animation (--animate): 60 s of a run at 25 frames/s"),
    "path_samples": Limit(10_000_000, "samples", "samples of one batch's table of VRU paths or of ego routes"),
    "delay_buffer_bytes": Limit(
        2_000_000_000, "bytes", "memory of one batch's sensor latency buffer and V2X message queues"
    ),
    "road_points": Limit(50_000, "points", "points of a scenario's drawn road (road.lines and road.surfaces)"),
    "road_samples": Limit(
        10_000_000,
        "samples",
        "points of an OpenDRIVE network sampled at once: to draw it or to project a position onto it",
    ),
}
"""Every limit by name (the environment variable is VRUSIM_LIMIT_ + the name in capitals)."""


def env_name(name: str) -> str:
    """The environment variable that changes limit `name`."""
    return f"VRUSIM_LIMIT_{name.upper()}"


_ENV_NAMES = {name: env_name(name) for name in LIMITS}
_PARSED: dict[tuple[str, str], float] = {}
"""Values read from the environment, by (limit, text): validation reads a limit per bounded field."""


_HELD: ContextVar[dict[str, float] | None] = ContextVar("vrusim_held_limits", default=None)
"""The limits read so far inside a `limits_held` block (None outside one)."""


@contextmanager
def limits_held() -> Iterator[None]:
    """Within the block, each limit is read from the environment once: for a batch of validations (a catalogue
    grid validates about 25,000 bounded fields), where a variable does not change between the checks."""
    token = _HELD.set({})
    try:
        yield
    finally:
        _HELD.reset(token)


def limit(name: str) -> float:
    """The value of limit `name`: its environment variable if set (a positive number), else the default."""
    held = _HELD.get()
    if held is None:
        return _read(name)
    value = held.get(name)
    if value is None:
        value = held[name] = _read(name)
    return value


def _read(name: str) -> float:
    text = os.environ.get(_ENV_NAMES[name])
    if text is None:
        return LIMITS[name].default
    parsed = _PARSED.get((name, text))
    if parsed is None:
        parsed = _PARSED[(name, text)] = _parse(name, text)
    return parsed


def _parse(name: str, text: str) -> float:
    """The limit `text` sets, or a UserInputError naming its variable."""
    entry = LIMITS[name]
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not value > 0 or value == float("inf"):
        raise UserInputError(f"{env_name(name)}: expected a positive number of {entry.unit}, got {text!r}")
    return value


def amount(value: float) -> str:
    """A count or size as text: whole numbers below 10^15 with thousands separators (2,000,000), others in
    Python's shortest form (0.25, 1e+308)."""
    number = float(value)
    if number.is_integer() and abs(number) < 1e15:
        return f"{int(value):,}"
    short = f"{number:g}"
    return short if float(short) == number else repr(number)


def excess(name: str, value: float) -> str | None:
    """Why `value` is beyond limit `name` (its magnitude is compared), or None when it is within:
    "<value> <unit> exceeds the limit of <limit> (<what the limit bounds>; <variable> raises it)"."""
    bound = limit(name)
    if not abs(value) > bound:
        return None
    entry = LIMITS[name]
    unit = f" {entry.unit}" if entry.unit else ""
    return f"{amount(value)}{unit} exceeds the limit of {amount(bound)} ({entry.bounds}; {env_name(name)} raises it)"


def check_limit(name: str, value: float, what: str) -> None:
    """Raise a UserInputError naming `what` if `value` exceeds limit `name`."""
    reason = excess(name, value)
    if reason is not None:
        raise UserInputError(f"{what}: {reason}")
