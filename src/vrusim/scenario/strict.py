"""The pydantic base of every user-written model (scenario, V2X channel, planner parameters, sweep spec).

Frozen, no unknown fields, no NaN or ±inf, defaults validated too, and **strict types**: a number field takes
only a number (an int or a float), a yes/no field only a boolean, a text field only a string. Pydantic's lax
mode would otherwise read `top_speed_mps: on` (YAML 1.1's `on` is `true`) as 1.0, `top_speed_mps: "1.5"` as
1.5 and `enabled: 1` as true, silently. Strictness lives in pydantic's compiled validators, so it costs no
validation time. Fields whose YAML form is not their Python type relax it with `Field(strict=False)`: an enum
written as its name, a tuple written as a YAML list.

Every field is also held to the physical bound of the unit in its name (coordinates, lengths, speeds,
accelerations: `vrusim.scenario.bounds`), so a huge but finite number is refused with the field's path.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from pydantic import BaseModel, ConfigDict, field_validator
from pydantic_core import ErrorDetails

from vrusim.scenario.bounds import BOUND_LIMITS, bound_of, value_excess


class StrictModel(BaseModel):
    """Base model: see the module docstring."""

    model_config = ConfigDict(extra="forbid", frozen=True, validate_default=True, allow_inf_nan=False, strict=True)

    def __init_subclass__(cls, **kwargs: Any) -> None:
        """Attach the bounds checks to the fields whose unit has one, one validator per limit (before pydantic
        collects validators: a validator on every field would make validation five times slower)."""
        super().__init_subclass__(**kwargs)
        names = {name for klass in cls.__mro__ for name in vars(klass).get("__annotations__", {})}
        for limit_name, check in _BOUND_CHECKS.items():
            bounded = sorted(name for name in names if bound_of(name) == limit_name)
            if bounded:
                validator = field_validator(*bounded, mode="after", check_fields=False)(check)
                setattr(cls, f"_bound_{limit_name}", validator)


def _bound_check(limit_name: str) -> Callable[[type, Any], Any]:
    """A validator: the value, or a ValueError when it is beyond limit `limit_name`."""

    def check(cls: type, value: Any) -> Any:
        reason = value_excess(limit_name, value)
        if reason is not None:
            raise ValueError(reason)
        return value

    return check


_BOUND_CHECKS = {name: _bound_check(name) for name in BOUND_LIMITS}


def the_one_given(model: BaseModel, names: tuple[str, ...]) -> str:
    """The name of the one field of `names` that `model` sets (not None); a ValueError "give exactly one of ..."
    when none or several are set (for a model validator)."""
    given = [name for name in names if getattr(model, name) is not None]
    if len(given) != 1:
        raise ValueError(f"give exactly one of {', '.join(names)}")
    return given[0]


def error_message(item: ErrorDetails) -> str:
    """One pydantic error as vrusim prints it after the field path: "unknown field" for a misspelt name, a
    wrong-type error with the value given (`Input should be a valid number, got true`), else pydantic's text."""
    if item["type"] == "extra_forbidden":
        return "unknown field"
    if item["type"] in ("tuple_type", "list_type"):  # "tuple" is Python's word; YAML writes a list
        return "Input should be a list"
    message = item["msg"].removeprefix("Value error, ")
    value = item.get("input")
    if item["type"].endswith("_type") and isinstance(value, bool | int | float | str):
        shown = str(value).lower() if isinstance(value, bool) else repr(value)
        message += f", got {shown}"
    return message
