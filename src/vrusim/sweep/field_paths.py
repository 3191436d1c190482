"""Dotted field paths as a sweep spec uses them (`set` and `parameters`): the scenario's paths, with sweep hints.

The paths themselves (parsing, checking, copy-on-write variants) live in `vrusim.scenario.field_paths`; a
sweep only adds that a field not set in the base scenario can be given a value under `set`, and that two
entries must not name one field (`check_overlaps`).
"""

from __future__ import annotations

from pydantic import BaseModel

from vrusim.errors import UserInputError
from vrusim.scenario import field_paths
from vrusim.scenario.field_paths import Step, parse_path, with_values

__all__ = ["Step", "check_overlaps", "check_path", "parse_path", "with_values"]

SWEEP_UNSET_HINT = "give it a value there (or under `set`) first"


def check_path(base: BaseModel, path: str, where: str = "parameters") -> tuple[Step, ...]:
    """The parsed path if it names a field of `base`; otherwise a UserInputError naming `where` and the step."""
    return field_paths.check_path(base, path, where, SWEEP_UNSET_HINT)


def _steps(path: str) -> tuple[Step, ...] | None:
    """The normalised steps of a path (`vrus[00]` is `vrus[0]`); None for a malformed one (refused later)."""
    try:
        return parse_path(path)
    except UserInputError:
        return None


def check_overlaps(paths: list[str], fixed: list[str]) -> None:
    """Refuse two `parameters` entries naming the same field (`vrus[0].x`, `vrus[00].x`), or a field followed by
    one of its parents (`ego.cruise_speed_mps`, then `ego`): values are applied in spec order, so the variant would
    take only the later value while the design records both. (A parent followed by its field is fine: the field's
    value overrides the parent's, e.g. `v2x.channel` then `v2x.channel.latency_s`.) The same for a `set` field
    and a parameter naming the same field written differently."""
    seen: list[tuple[tuple[Step, ...], str]] = []
    for path in paths:
        steps = _steps(path)
        if steps is None:
            continue
        for earlier_steps, earlier in seen:
            if steps == earlier_steps:
                raise UserInputError(f"parameters: {earlier!r} and {path!r} name the same field; give it once")
            if earlier_steps[: len(steps)] == steps:
                raise UserInputError(
                    f"parameters: {earlier!r} and {path!r} overlap: {earlier} is part of {path}, which comes later "
                    f"and would overwrite it in every variant; give {path!r} first (its fields then override it) "
                    "or sweep only one of them"
                )
        seen.append((steps, path))
    for path in fixed:
        steps = _steps(path)
        for earlier_steps, earlier in seen:
            if steps == earlier_steps:
                raise UserInputError(
                    f"set.{path}: the same field as parameters.{earlier}; a field is either fixed (set) or swept "
                    "(parameters), not both"
                )
