"""Dotted field paths into a scenario (`ego.cruise_speed_mps`, `vrus[0].trigger.at_time_s`) and validated copies.

A path names a field by its YAML keys, with `[i]` for a list element. `check_path` walks a validated model
and explains an unknown step; `with_values` builds a copy by copy-on-write: only the models on the changed
paths are rebuilt (and validated again, with the model's own validators), every other part is shared with the
base, so a copy costs tens of microseconds instead of a full validation. `Scenario.replace` and the sweep's
variants are built this way.
"""

from __future__ import annotations

import difflib
import re
from collections.abc import Sequence
from typing import Any, TypeVar

from pydantic import BaseModel, ValidationError

from vrusim.errors import UserInputError
from vrusim.scenario.strict import error_message
from vrusim.scenario.v2x import resolve_channel

_STEP = re.compile(r"([A-Za-z_][A-Za-z0-9_]*)((?:\[\d+\])*)")

Step = str | int
"""A field name or a list index."""

Model = TypeVar("Model", bound=BaseModel)

UNSET_HINT = "give it a value first"
"""What `check_path` suggests for a path through a field that is not set (None)."""


def parse_path(path: str, where: str = "parameters") -> tuple[Step, ...]:
    """The steps of a dotted path; a malformed path raises UserInputError naming `where`."""
    steps: list[Step] = []
    for part in path.split("."):
        match = _STEP.fullmatch(part.strip())
        if match is None:
            raise UserInputError(
                f"{where}: {path!r} is not a field path; expected names joined by '.', with [i] for a list "
                "element, e.g. vrus[0].top_speed_mps"
            )
        steps.append(match.group(1))
        steps.extend(int(index) for index in re.findall(r"\[(\d+)\]", match.group(2)))
    return tuple(steps)


def render_path(steps: Sequence[Step]) -> str:
    """Steps written as a dotted path, e.g. `vrus[0].top_speed_mps` ("" for no steps)."""
    text = ""
    for step in steps:
        text += f"[{step}]" if isinstance(step, int) else (f".{step}" if text else str(step))
    return text


def field_path(location: tuple[int | str, ...]) -> str:
    """Render a pydantic error location as a dotted path, e.g. `vrus[0].top_speed_mps`."""
    return render_path(location) or "(top level)"


MAX_LISTED_ERRORS = 8
"""At most this many offending fields are listed in one message (the rest are counted)."""


def describe_validation_error(error: ValidationError, source: str, what: str = "scenario") -> str:
    """One readable message listing the offending fields (at most MAX_LISTED_ERRORS) and what was expected."""
    lines = [f"{source}: invalid {what}"]
    items = error.errors(include_url=False)
    for item in items[:MAX_LISTED_ERRORS]:
        location = tuple(p for p in item["loc"] if p not in ("function-after[_from_pair(), Point]",))
        lines.append(f"  {field_path(location)}: {error_message(item)}")
    if len(items) > MAX_LISTED_ERRORS:
        lines.append(f"  ... and {len(items) - MAX_LISTED_ERRORS} more")
    return "\n".join(lines)


def _expanded(node: Any, field: str) -> Any:
    """A node as it can be walked into: a channel profile name becomes its specification."""
    if field == "channel" and isinstance(node, str):
        return resolve_channel(node)
    return node


def check_path(base: BaseModel, path: str, where: str = "parameters", unset_hint: str = UNSET_HINT) -> tuple[Step, ...]:
    """The parsed path if it names a field of `base`; otherwise a UserInputError saying which step is wrong."""
    steps = parse_path(path, where)
    node: Any = base
    parent_field = ""
    for depth, step in enumerate(steps):
        node = _expanded(node, parent_field)
        here = render_path(steps[:depth]) or "the scenario"
        if isinstance(step, int):
            if not isinstance(node, list):
                raise UserInputError(f"{where}: {path}: {here} is not a list")
            if step >= len(node):
                raise UserInputError(f"{where}: {path}: {here} has {len(node)} element(s), no [{step}]")
            node = node[step]
            continue
        if isinstance(node, BaseModel):
            fields = list(type(node).model_fields)
            if step not in fields:
                close = difflib.get_close_matches(step, fields, n=1)
                hint = f" (did you mean {close[0]}?)" if close else ""
                raise UserInputError(
                    f"{where}: {path}: unknown field {step!r} in {here}{hint}; expected one of: {', '.join(fields)}"
                )
            node = getattr(node, step)
        elif isinstance(node, dict):
            node = node.get(step)
        elif node is None:
            raise UserInputError(f"{where}: {path}: {here} is not set in the base scenario; {unset_hint}")
        else:
            raise UserInputError(f"{where}: {path}: {here} is a value ({node!r}), it has no field {step!r}")
        parent_field = step
    return steps


def _replace(node: Any, steps: Sequence[Step], value: Any, parent_field: str = "") -> Any:
    """`node` with the field at `steps` set to `value`; changed models become mappings, the rest is shared."""
    if not steps:
        return value
    node = _expanded(node, parent_field)
    step, rest = steps[0], steps[1:]
    if isinstance(step, int):
        items = list(node)
        items[step] = _replace(items[step], rest, value)
        return items
    # a model's field values are its __dict__ (pydantic keeps them there); copying it is the fast way
    mapping = node.__dict__.copy() if isinstance(node, BaseModel) else dict(node) if isinstance(node, dict) else {}
    mapping[step] = _replace(mapping.get(step), rest, value, step)
    return mapping


def with_values(base: Model, assignments: Sequence[tuple[tuple[Step, ...], Any]], source: str) -> Model:
    """A validated copy of `base` with each (path steps, value) assigned; UserInputError names the field."""
    tree: Any = base
    for steps, value in assignments:
        tree = _replace(tree, steps, value)
    if isinstance(tree, type(base)):
        return tree
    try:
        return type(base).model_validate(tree)
    except ValidationError as error:
        raise UserInputError(describe_validation_error(error, source)) from None


def replaced(base: Model, changes: dict[str, Any], where: str) -> Model:
    """A validated copy of `base` with the field at each dotted path of `changes` set to its value.

    An unknown path or a value the model refuses raises UserInputError naming `where` and the path.
    """
    assignments = [(check_path(base, path, where), value) for path, value in changes.items()]
    return with_values(base, assignments, where) if assignments else base
