"""Parameter and variable conditions, and the VariableActions that change variables, resolved when the file is read.

- ParameterCondition: parameters do not change during a run (ParameterSetAction / ParameterModifyAction,
  deprecated in OpenSCENARIO 1.2, are refused), so it holds from t = 0 or never (`StaticCondition`).
- VariableAction (in an event): SetAction, or ModifyAction by AddValue / MultiplyByValue.
- VariableCondition: holds from t = 0 when the declared value satisfies it; else from the start of the event whose
  VariableAction first makes it true: with one event changing the variable, that event's start; with several,
  their starts must all be simulation times (the changes are applied in time order, ties in file order).
"""

from __future__ import annotations

from collections.abc import Callable

from vrusim.formats.xml_file import Element, shown
from vrusim.formats.xosc_condition_kinds import RULES, StaticCondition, VariableChange, VariableTest, compare
from vrusim.formats.xosc_document import XoscDocument
from vrusim.formats.xosc_expression import Value
from vrusim.formats.xosc_model import Condition
from vrusim.formats.xosc_parameters import convert


def _typed(doc: XoscDocument, element: Element, like: Value | str, attribute: str = "value") -> Value | str:
    """Attribute `attribute` of `element` converted to the type of `like` (number, boolean or text)."""
    if isinstance(like, bool):
        return doc.choice(element, attribute, ("true", "false")) == "true"
    if isinstance(like, float):
        return doc.number(element, attribute)
    return doc.text(element, attribute)


def _compared(doc: XoscDocument, element: Element, left: Value | str, rule: str, right: Value | str) -> bool:
    try:
        return compare(left, rule, right)
    except ValueError as error:
        raise doc.fail(element, f"attribute rule: {error}") from None


def declared_value(doc: XoscDocument, element: Element, name: str) -> Value | str:
    """The declared value of variable `name` (a number, a boolean or text); undeclared: an error at `element`."""
    if name not in doc.variables:
        raise doc.fail(element, f"variable {shown(name)} is not declared (<VariableDeclarations>)")
    return convert(doc.variables[name], "infer")[1]


def declared_values(doc: XoscDocument) -> dict[str, Value | str]:
    """Every declared variable's value (number, boolean or text)."""
    return {name: convert(text, "infer")[1] for name, text in doc.variables.items()}


def read_parameter_condition(doc: XoscDocument, element: Element) -> StaticCondition:
    """A `<ParameterCondition>`: "always" or "never" (the parameter's value after overrides)."""
    doc.children(element, set())
    name = doc.raw(element, "parameterRef")
    if name not in doc.values:
        raise doc.fail(element, f"attribute parameterRef: parameter {shown(name)} is not declared")
    rule = doc.choice(element, "rule", RULES)
    value = doc.values[name]
    holds = _compared(doc, element, value, rule, _typed(doc, element, value))
    return StaticCondition("always" if holds else "never", line=element.line, tag=element.tag)


def read_variable_condition(doc: XoscDocument, element: Element) -> VariableTest:
    """A `<VariableCondition>` (resolved later by `variable_start`)."""
    doc.children(element, set())
    name = doc.raw(element, "variableRef")
    declared = declared_value(doc, element, name)
    rule = doc.choice(element, "rule", RULES)
    operand = _typed(doc, element, declared)
    _compared(doc, element, declared, rule, operand)
    return VariableTest("variable", ref=name, rule=rule, operand=operand, line=element.line)


def read_variable_action(doc: XoscDocument, element: Element, event: str) -> VariableChange:
    """A `<VariableAction>` of event `event`."""
    name = doc.raw(element, "variableRef")
    declared = declared_value(doc, element, name)
    action = doc.single(element, {"SetAction", "ModifyAction"})
    if action.tag == "SetAction":
        doc.children(action, set())
        return VariableChange(event, name, "set", _typed(doc, action, declared), action.line)
    rule = doc.single(doc.single(action, {"Rule"}), {"AddValue", "MultiplyByValue"})
    doc.children(rule, set())
    if not isinstance(declared, float):
        raise doc.fail(rule, f"variable {shown(name)} is not a number")
    operation = "add" if rule.tag == "AddValue" else "multiply"
    return VariableChange(event, name, operation, doc.number(rule, "value"), rule.line)


def _applied(value: Value | str, change: VariableChange) -> Value | str:
    if change.operation == "set":
        return change.value
    assert isinstance(value, float) and isinstance(change.value, float)
    return value + change.value if change.operation == "add" else value * change.value


def variable_start(
    test: VariableTest,
    declared: Value | str,
    changes: list[VariableChange],
    event_time: Callable[[str], float | None],
    refuse: Callable[[str], Exception],
) -> Condition:
    """The condition equivalent to `test`: "always", "never", the start of one event ("event_start") or a "time".
    `event_time(event)`: the event's start time when it starts at a simulation time, else None."""
    if compare(declared, test.rule, test.operand):
        return StaticCondition("always", line=test.line, tag=test.tag)
    mine = [c for c in changes if c.name == test.ref]
    if len(mine) == 1:
        if not compare(_applied(declared, mine[0]), test.rule, test.operand):
            return StaticCondition("never", line=test.line, tag=test.tag)
        return Condition("event_start", ref=mine[0].event, line=test.line)
    times = [event_time(c.event) for c in mine]
    if any(t is None for t in times):
        raise refuse(
            f"variable {shown(test.ref)} is changed by several events that do not all start at a simulation "
            "time: the order of the changes is not known before the run"
        )
    value = declared
    for time_s, change in sorted(zip(times, mine, strict=True), key=lambda pair: pair[0]):  # type: ignore[arg-type, return-value]
        value = _applied(value, change)
        if compare(value, test.rule, test.operand):
            return Condition("time", float(time_s), line=test.line)  # type: ignore[arg-type]
    return StaticCondition("never", line=test.line, tag=test.tag)
