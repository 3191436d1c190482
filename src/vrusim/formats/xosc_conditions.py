"""Read OpenSCENARIO triggers into `Condition`s: simulation time, travelled distance, event started, collision.

A start trigger must be one condition (one `<ConditionGroup>` holding one `<Condition>`); a stop trigger may have
several groups (OR-ed), each of one condition. Any other condition kind is refused. A simulation-time
condition's delay is added to its time; a travelled-distance condition may not be delayed.
"""

from __future__ import annotations

from vrusim.formats.xml_file import Element
from vrusim.formats.xosc_document import XoscDocument
from vrusim.formats.xosc_model import Condition

_EDGES = ("none", "rising")


def _time(doc: XoscDocument, element: Element, delay_s: float) -> Condition:
    doc.children(element, set())
    doc.choice(element, "rule", ("greaterOrEqual", "greaterThan"))
    return Condition("time", doc.number(element, "value") + delay_s, line=element.line)


def _event_started(doc: XoscDocument, element: Element, delay_s: float) -> Condition:
    doc.children(element, set())
    doc.choice(element, "storyboardElementType", ("event",))
    doc.choice(element, "state", ("startTransition", "runningState"))
    ref = doc.text(element, "storyboardElementRef")
    return Condition("event_start", ref=ref, delay_s=delay_s, line=element.line)


def _by_entity(doc: XoscDocument, element: Element, delay_s: float) -> Condition:
    doc.children(element, {"TriggeringEntities", "EntityCondition"})
    entities = doc.child(element, "TriggeringEntities")
    doc.choice(entities, "triggeringEntitiesRule", ("any", "all"))
    refs = doc.children(entities, {"EntityRef"})
    if len(refs) != 1:
        raise doc.fail(entities, "needs exactly one <EntityRef>")
    ref = doc.text(refs[0], "entityRef")
    condition = doc.single(doc.child(element, "EntityCondition"), {"TraveledDistanceCondition", "CollisionCondition"})
    if condition.tag == "TraveledDistanceCondition":
        doc.children(condition, set())
        if delay_s != 0.0:
            raise doc.fail(element, "a delayed travelled-distance condition is not supported")
        return Condition("travel", doc.number(condition, "value"), ref=ref, line=condition.line)
    target = doc.single(condition, {"EntityRef"})
    return Condition("collision", ref=ref, other=doc.text(target, "entityRef"), line=condition.line)


def read_condition(doc: XoscDocument, element: Element) -> Condition:
    """One `<Condition>`."""
    doc.choice(element, "conditionEdge", _EDGES)
    delay = doc.number(element, "delay", 0.0)
    if delay < 0:
        raise doc.fail(element, "attribute delay: must be >= 0")
    kind = doc.single(element, {"ByValueCondition", "ByEntityCondition"})
    if kind.tag == "ByEntityCondition":
        return _by_entity(doc, kind, delay)
    value = doc.single(kind, {"SimulationTimeCondition", "StoryboardElementStateCondition"})
    if value.tag == "SimulationTimeCondition":
        return _time(doc, value, delay)
    return _event_started(doc, value, delay)


def read_trigger(doc: XoscDocument, trigger: Element, single: bool) -> list[Condition]:
    """The conditions of a start or stop trigger (OR-ed groups of one condition each); `single`: exactly one."""
    groups = doc.children(trigger, {"ConditionGroup"})
    conditions = []
    for group in groups:
        inside = doc.children(group, {"Condition"})
        if len(inside) != 1:
            raise doc.fail(group, "needs exactly one <Condition> (AND-ed conditions are not supported)")
        conditions.append(read_condition(doc, inside[0]))
    if single and len(conditions) != 1:
        raise doc.fail(trigger, f"needs exactly one <ConditionGroup>, has {len(conditions)}")
    return conditions
