"""OpenSCENARIO parameter types: a declared (or given) value text checked and converted to its type.

Types (ASAM OpenSCENARIO 1.x `ParameterType`): double, int (1.0's `integer` too), unsignedInt, unsignedShort,
boolean, string, dateTime. A number written where an int is declared must be whole ("3", "3.0"); the result of an
expression (`${...}`) is converted the same way, so `${$a / 2}` into an int is refused unless it is whole
(use round, floor or ceil). Without a parameterType the value is a number when it reads as one, a boolean when
it is true or false, else a string.
"""

from __future__ import annotations

import math
from datetime import datetime

from vrusim.formats.xosc_expression import Value

TYPES = ("double", "int", "integer", "unsignedInt", "unsignedShort", "boolean", "string", "dateTime")
_BOUNDS = {
    "int": (-(2**31), 2**31 - 1),
    "integer": (-(2**31), 2**31 - 1),
    "unsignedInt": (0, 2**32 - 1),
    "unsignedShort": (0, 2**16 - 1),
}
"""Inclusive range of each integer type."""


def parameter_type(text: str) -> str | None:
    """The type named by a parameterType attribute ("" = not given, "infer"), or None when it is unknown."""
    if text == "":
        return "infer"
    return text if text in TYPES else None


def _double(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise ValueError(f"expected a number, got {text[:40]!r}") from None
    if not math.isfinite(value):
        raise ValueError(f"expected a finite number, got {text[:40]!r}")
    return value


def convert(text: str, kind: str) -> tuple[str, Value | str]:
    """(attribute text, typed value) of `text` as a parameter of type `kind` (a name from TYPES or "infer");
    a value that does not fit the type raises ValueError saying why."""
    if len(text) > 200 and kind not in ("string", "infer"):
        raise ValueError(f"{len(text)} characters is too long for a {kind}")
    if kind == "double":
        value = _double(text)
        return text, value
    if kind in _BOUNDS:
        number = _double(text)
        low, high = _BOUNDS[kind]
        if not number.is_integer() or not low <= number <= high:
            raise ValueError(f"expected a whole number in [{low}, {high}] ({kind}), got {text[:40]!r}")
        return str(int(number)), float(number)
    if kind == "boolean":
        if text not in ("true", "false"):
            raise ValueError(f"expected true or false (boolean), got {text[:40]!r}")
        return text, text == "true"
    if kind == "dateTime":
        try:
            datetime.fromisoformat(text)
        except ValueError:
            raise ValueError(f"expected a date and time (ISO 8601), got {text[:40]!r}") from None
        return text, text
    if kind == "infer":
        if text in ("true", "false"):
            return text, text == "true"
        try:
            return text, _double(text)
        except ValueError:
            return text, text
    return text, text
