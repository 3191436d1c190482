"""Read OpenSCENARIO triggers into `Condition`s.

Read: SimulationTimeCondition ("time"; with rule lessThan / lessOrEqual and edge falling "time_before"),
TraveledDistanceCondition ("travel"), StoryboardElementStateCondition of an event ("event_start"),
CollisionCondition ("collision"), ReachPositionCondition, DistanceCondition and RelativeDistanceCondition
("distance", euclidean, approaching: rule lessThan / lessOrEqual), TimeToCollisionCondition to a position or an
entity ("ttc"), SpeedCondition, StandStillCondition, RelativeSpeedCondition ("speed", "standstill"),
ParameterCondition ("always" / "never") and VariableCondition ("variable"; `xosc_condition_kinds`). Which of them a
VRU trigger, a driver phase or the stop trigger can use is decided when the scenario is built (`xosc_triggers`,
`xosc_condition_logic`). Other conditions are refused. A trigger is OR-ed `<ConditionGroup>`s (several give an
`AnyCondition`) of AND-ed conditions (several give an `AllCondition`). A simulation-time condition's delay is
added to its time; other conditions keep theirs in `delay_s`. Edges `none`, `rising` and `risingOrFalling` are
read alike (a condition counts as false before the run, so its first change is its rise, at t = 0 when
it holds then); `falling` wraps the
condition in a `FallingCondition`.
"""

from __future__ import annotations

from vrusim.formats.xml_file import Element
from vrusim.formats.xodr_model import Network
from vrusim.formats.xosc_condition_kinds import AllCondition, FallingCondition
from vrusim.formats.xosc_document import XoscDocument
from vrusim.formats.xosc_model import AnyCondition, Condition, PlaceCondition
from vrusim.formats.xosc_positions import read_position
from vrusim.formats.xosc_speed_conditions import read_speed
from vrusim.formats.xosc_variables import read_parameter_condition, read_variable_condition

_EDGES = ("none", "rising", "risingOrFalling", "falling")
_SPEEDS = ("SpeedCondition", "StandStillCondition", "RelativeSpeedCondition")
_APPROACH = ("lessThan", "lessOrEqual")
_REFUSED = {
    "AccelerationCondition": "vrusim triggers do not start on an acceleration",
    "TimeHeadwayCondition": "vrusim triggers do not start on a time headway",
    "EndOfRoadCondition": "vrusim triggers do not start at the end of a road",
    "OffroadCondition": "vrusim triggers do not start off road",
    "RelativeClearanceCondition": "vrusim triggers do not start on a clearance",
}
_BY_ENTITY = {
    "TraveledDistanceCondition",
    "CollisionCondition",
    "ReachPositionCondition",
    "DistanceCondition",
    "RelativeDistanceCondition",
    "TimeToCollisionCondition",
    *_SPEEDS,
    *_REFUSED,
}


class _ConditionReader:
    def __init__(self, doc: XoscDocument, network: Network | None) -> None:
        self.doc, self.network = doc, network

    def point(self, element: Element) -> tuple[float, float]:
        if self.network is None:
            raise self.doc.fail(element, "is not supported here")
        pose = read_position(self.doc, element, self.network)
        return pose.x_m, pose.y_m

    def euclidean(self, element: Element) -> None:
        """Refuse distances that are not straight-line distances in the entity's frame."""
        doc = self.doc
        doc.choice(element, "relativeDistanceType", ("euclidianDistance", "euclideanDistance"), "euclidianDistance")
        doc.choice(element, "coordinateSystem", ("entity",), "entity")
        doc.choice(element, "alongRoute", ("false", "0"), "false")

    def freespace(self, element: Element) -> bool:
        return self.doc.choice(element, "freespace", ("true", "false", "1", "0")) in ("true", "1")

    def time(self, element: Element, delay_s: float) -> Condition:
        doc = self.doc
        doc.children(element, set())
        doc.choice(element, "rule", ("greaterOrEqual", "greaterThan"))
        return Condition("time", doc.number(element, "value") + delay_s, line=element.line)

    def event_started(self, element: Element, delay_s: float) -> Condition:
        doc = self.doc
        doc.children(element, set())
        doc.choice(element, "storyboardElementType", ("event",))
        doc.choice(element, "state", ("startTransition", "runningState"))
        ref = doc.text(element, "storyboardElementRef")
        return Condition("event_start", ref=ref, delay_s=delay_s, line=element.line)

    def by_entity(self, element: Element, delay_s: float) -> Condition:
        doc = self.doc
        doc.children(element, {"TriggeringEntities", "EntityCondition"})
        entities = doc.child(element, "TriggeringEntities")
        doc.choice(entities, "triggeringEntitiesRule", ("any", "all"))
        refs = doc.children(entities, {"EntityRef"})
        if len(refs) != 1:
            raise doc.fail(entities, "needs exactly one <EntityRef>")
        ref = doc.text(refs[0], "entityRef")
        condition = doc.single(doc.child(element, "EntityCondition"), _BY_ENTITY)
        if condition.tag in _REFUSED:
            raise doc.fail(condition, f"is not supported: {_REFUSED[condition.tag]}")
        if condition.tag == "TraveledDistanceCondition":
            doc.children(condition, set())
            return Condition("travel", doc.number(condition, "value"), ref=ref, delay_s=delay_s, line=condition.line)
        if condition.tag in _SPEEDS:
            return read_speed(doc, condition, ref, delay_s)
        if condition.tag == "CollisionCondition":
            target = doc.single(condition, {"EntityRef"})
            return Condition("collision", ref=ref, other=doc.text(target, "entityRef"), line=condition.line)
        return self.place(condition, ref, delay_s)

    def place(self, element: Element, ref: str, delay_s: float) -> PlaceCondition:
        """A ReachPosition, Distance, RelativeDistance or TimeToCollision condition of entity `ref`."""
        doc, line, tag = self.doc, element.line, element.tag
        if element.tag == "ReachPositionCondition":
            x, y = self.point(doc.single(element, {"Position"}))
            tolerance = doc.number(element, "tolerance")
            return PlaceCondition("distance", tolerance, ref=ref, delay_s=delay_s, line=line, x_m=x, y_m=y, tag=tag)
        self.euclidean(element)
        doc.choice(element, "rule", _APPROACH)
        value, freespace = doc.number(element, "value"), self.freespace(element)
        common = {"ref": ref, "delay_s": delay_s, "line": line, "freespace": freespace, "tag": tag}
        if element.tag == "DistanceCondition":
            x, y = self.point(doc.single(element, {"Position"}))
            return PlaceCondition("distance", value, x_m=x, y_m=y, **common)
        if element.tag == "RelativeDistanceCondition":
            doc.children(element, set())
            return PlaceCondition("distance", value, other=doc.text(element, "entityRef"), **common)
        target = doc.single(doc.single(element, {"TimeToCollisionConditionTarget"}), {"Position", "EntityRef"})
        if target.tag == "EntityRef":
            return PlaceCondition("ttc", value, other=doc.text(target, "entityRef"), **common)
        x, y = self.point(target)
        return PlaceCondition("ttc", value, x_m=x, y_m=y, **common)

    def condition(self, element: Element) -> Condition:
        doc = self.doc
        edge = doc.choice(element, "conditionEdge", _EDGES)
        delay = doc.number(element, "delay", 0.0)
        if delay < 0:
            raise doc.fail(element, "attribute delay: must be >= 0")
        read = self.by_value(doc.single(element, {"ByValueCondition", "ByEntityCondition"}), delay, edge)
        if edge == "falling":
            return FallingCondition("falling", line=element.line, inner=read)
        return read

    def by_value(self, kind: Element, delay: float, edge: str) -> Condition:
        """A `<ByEntityCondition>` or `<ByValueCondition>` (a time condition with rule lessThan / lessOrEqual
        only for a falling edge)."""
        doc = self.doc
        if kind.tag == "ByEntityCondition":
            return self.by_entity(kind, delay)
        allowed = {"SimulationTimeCondition", "StoryboardElementStateCondition", "VariableCondition"}
        value = doc.single(kind, allowed | {"ParameterCondition"})
        if value.tag in ("VariableCondition", "ParameterCondition"):
            if delay != 0.0:
                raise doc.fail(value, "a delay is not supported on a parameter or variable condition")
            if value.tag == "ParameterCondition":
                return read_parameter_condition(doc, value)
            return read_variable_condition(doc, value)
        if value.tag == "SimulationTimeCondition":
            if edge == "falling" and doc.text(value, "rule") in ("lessThan", "lessOrEqual"):
                doc.children(value, set())
                return Condition("time_before", doc.number(value, "value") + delay, line=value.line)
            return self.time(value, delay)
        return self.event_started(value, delay)


def read_condition(doc: XoscDocument, element: Element, network: Network | None = None) -> Condition:
    """One `<Condition>` (positions need the road `network`)."""
    return _ConditionReader(doc, network).condition(element)


def read_conditions(doc: XoscDocument, trigger: Element, network: Network | None = None) -> list[Condition]:
    """The conditions of a trigger, one per `<ConditionGroup>` (OR-ed)."""
    groups = doc.children(trigger, {"ConditionGroup"})
    conditions = []
    for group in groups:
        inside = [read_condition(doc, c, network) for c in doc.children(group, {"Condition"})]
        if not inside:
            raise doc.fail(group, "needs at least one <Condition>")
        conditions.append(
            inside[0] if len(inside) == 1 else AllCondition("all", line=group.line, options=tuple(inside))
        )
    return conditions


def read_trigger(doc: XoscDocument, trigger: Element, single: bool, network: Network | None = None) -> list[Condition]:
    """The conditions of a trigger (OR-ed groups of one condition each). `single`: a start trigger, returned as one
    condition (an `AnyCondition` when it has several groups)."""
    conditions = read_conditions(doc, trigger, network)
    if not single:
        return conditions
    if not conditions:
        raise doc.fail(trigger, "needs at least one <ConditionGroup>")
    if len(conditions) == 1:
        return conditions
    return [AnyCondition("any", line=trigger.line, options=tuple(conditions))]
