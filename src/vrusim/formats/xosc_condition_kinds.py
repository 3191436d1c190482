"""The start conditions beyond `xosc_model`'s, as frozen dataclasses (read by `xosc_conditions`, mapped by
`xosc_condition_logic`).

- `SpeedTest`: "speed" (SpeedCondition, RelativeSpeedCondition: the speed of `ref`, minus that of `other` when
  given, compared by `rule` with `value` m/s) or "standstill" (StandStillCondition: `ref` at speed 0 for `value` s);
- `StaticCondition`: "always" / "never", a condition whose truth is known when the file is read
  (ParameterCondition);
- `VariableTest`: "variable", a VariableCondition (`ref`: the variable, compared by `rule` with `operand`);
- `AllCondition`: "all", the AND-ed conditions of one `<ConditionGroup>`;
- `FallingCondition`: "falling", a condition with conditionEdge falling: the instant `inner` stops holding after
  it has held.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from vrusim.formats.xosc_expression import Value
from vrusim.formats.xosc_model import Condition

RULES = ("greaterThan", "greaterOrEqual", "lessThan", "lessOrEqual", "equalTo", "notEqualTo")
NEGATED = {
    "greaterThan": "lessOrEqual",
    "greaterOrEqual": "lessThan",
    "lessThan": "greaterOrEqual",
    "lessOrEqual": "greaterThan",
    "equalTo": "notEqualTo",
    "notEqualTo": "equalTo",
}
"""The rule that holds exactly when a rule does not."""


def compare(left: Value | str, rule: str, right: Value | str) -> bool:
    """`left rule right` (OpenSCENARIO `Rule`); numbers within 1e-9 are equal; booleans and text compare only
    with equalTo / notEqualTo (a size comparison of them raises ValueError)."""
    if isinstance(left, float) and isinstance(right, float):
        equal = math.isclose(left, right, rel_tol=0.0, abs_tol=1e-9)
        if rule in ("equalTo", "notEqualTo"):
            return equal == (rule == "equalTo")
        if rule in ("greaterOrEqual", "lessOrEqual"):
            return equal or (left > right) == (rule == "greaterOrEqual")
        return not equal and (left > right) == (rule == "greaterThan")
    if rule not in ("equalTo", "notEqualTo"):
        raise ValueError(f"rule {rule} compares numbers only")
    return (left == right) == (rule == "equalTo")


NEVER = Condition("never")


@dataclass(frozen=True)
class SpeedTest(Condition):
    """ "speed" or "standstill" (above); `tag`: the element read."""

    rule: str = "greaterOrEqual"
    tag: str = ""


@dataclass(frozen=True)
class StaticCondition(Condition):
    """ "always" or "never"; `tag`: the element read."""

    tag: str = ""


@dataclass(frozen=True)
class VariableTest(Condition):
    """ "variable": variable `ref` compared by `rule` with `operand` (typed like the variable)."""

    rule: str = "equalTo"
    operand: Value | str = 0.0
    tag: str = "VariableCondition"


@dataclass(frozen=True)
class AllCondition(Condition):
    """ "all": holds when every one of `options` holds at the same instant."""

    options: tuple[Condition, ...] = ()
    tag: str = "ConditionGroup"


@dataclass(frozen=True)
class FallingCondition(Condition):
    """ "falling": the first instant `inner` stops holding after it has held."""

    inner: Condition = NEVER
    tag: str = "Condition"


@dataclass(frozen=True)
class VariableChange:
    """A VariableAction of event `event`: "set" `value`, or "add" / "multiply" by it, on variable `name`."""

    event: str
    name: str
    operation: str
    value: Value | str
    line: int
