"""The pydantic base of every user-written model (scenario, V2X channel, planner parameters, sweep spec).

Frozen, no unknown fields, no NaN or ±inf, defaults validated too; and a number field takes only a number,
a yes/no field only a boolean. Pydantic's lax mode would otherwise read `top_speed_mps: on` (YAML 1.1's
`on` is `true`) as 1.0, `top_speed_mps: "1.5"` as 1.5 and `enabled: 1` as true, silently.
"""

from __future__ import annotations

import types
from functools import cache
from typing import Any, Union, get_args, get_origin

import numpy as np
from pydantic import BaseModel, ConfigDict, ValidationInfo, field_validator

_NUMBER_TYPES = (int, float)


@cache
def _expected_kind(annotation: Any) -> str | None:
    """ "number" or "boolean" when a field of this annotation must be exactly that (None allowed), else None."""
    if get_origin(annotation) in (Union, types.UnionType):
        kinds = {_expected_kind(arg) for arg in get_args(annotation) if arg is not type(None)}
        return kinds.pop() if len(kinds) == 1 else None
    if annotation is bool:
        return "boolean"
    if annotation in _NUMBER_TYPES:
        return "number"
    return None


def _type_word(value: Any) -> str:
    if isinstance(value, bool | np.bool_):
        return "a boolean"
    return {str: "a string", int: "a number", float: "a number"}.get(type(value), f"a {type(value).__name__}")


class StrictModel(BaseModel):
    """Base model: see the module docstring."""

    model_config = ConfigDict(extra="forbid", frozen=True, validate_default=True, allow_inf_nan=False)

    @field_validator("*", mode="before")
    @classmethod
    def _exact_scalar_types(cls, value: Any, info: ValidationInfo) -> Any:
        field = cls.model_fields.get(info.field_name or "")
        kind = None if field is None else _expected_kind(field.annotation)
        if kind == "number" and isinstance(value, bool | np.bool_ | str):
            raise ValueError(f"expected a number, got {_type_word(value)} ({value!r})")
        if kind == "boolean" and not isinstance(value, bool | np.bool_) and value is not None:
            raise ValueError(f"expected true or false, got {_type_word(value)} ({value!r})")
        return value
