"""Read `<SynchronizeAction>` and `<LongitudinalDistanceAction>` (ASAM OpenSCENARIO XML 1.3) into the model.

SynchronizeAction (a PrivateAction): `masterEntityRef`, `targetToleranceMaster` and `targetTolerance` (m, default
0), `<TargetPositionMaster>` and `<TargetPosition>` (positions), optional `<FinalSpeed>`: `<AbsoluteSpeed value>` or
`<RelativeSpeedToMaster speedTargetValueType="delta|factor" value>`, each with an optional steady state
`<TargetDistanceSteadyState distance>` or `<TargetTimeSteadyState time>`. What vrusim makes of it:
`xosc_sync_vru`.

LongitudinalDistanceAction (in a LongitudinalAction): `entityRef`, `distance` or `timeGap`, `freespace`,
`displacement` (default trailingReferencedEntity), `coordinateSystem` entity only, `continuous` false only and no
`<DynamicConstraints>`, at t = 0 only: a placement relative to the referenced entity (`xosc_longitudinal`).
"""

from __future__ import annotations

from vrusim.formats.xml_file import Element
from vrusim.formats.xodr_model import Network
from vrusim.formats.xosc_document import XoscDocument
from vrusim.formats.xosc_model import Condition, FinalSpeed, Placement, Synchronize
from vrusim.formats.xosc_positions import read_position

SYNC_ACTIONS = {"SynchronizeAction"}
"""Private actions read here besides those of `xosc_actions`."""
DISPLACEMENTS = {"trailingReferencedEntity": "trailing", "leadingReferencedEntity": "leading", "any": "any"}


def read_synchronize(
    doc: XoscDocument, action: Element, network: Network, event: str, condition: Condition
) -> Synchronize:
    """The `<SynchronizeAction>` `action` of event `event` (Init: ""), started by `condition`."""
    doc.children(action, {"TargetPositionMaster", "TargetPosition", "FinalSpeed"})
    master_element, target_element = doc.child(action, "TargetPositionMaster"), doc.child(action, "TargetPosition")
    tolerances = []
    for name in ("targetToleranceMaster", "targetTolerance"):
        value = doc.number(action, name, 0.0)
        if value < 0:
            raise doc.fail(action, f"attribute {name} must be >= 0, got {value:g}")
        tolerances.append(value)
    final = doc.optional(action, "FinalSpeed")
    return Synchronize(
        event=event,
        master=doc.text(action, "masterEntityRef"),
        master_target=read_position(doc, master_element, network),
        target=read_position(doc, target_element, network),
        master_tolerance_m=tolerances[0],
        tolerance_m=tolerances[1],
        final=_final_speed(doc, final) if final is not None else None,
        condition=condition,
        line=action.line,
        master_line=master_element.line,
        target_line=target_element.line,
    )


def _final_speed(doc: XoscDocument, final: Element) -> FinalSpeed:
    speed = doc.single(final, {"AbsoluteSpeed", "RelativeSpeedToMaster"})
    steady = doc.children(speed, {"TargetDistanceSteadyState", "TargetTimeSteadyState", "SteadyState"})
    if speed.tag == "AbsoluteSpeed":
        kind, value = "absolute", doc.number(speed, "value")
        if value < 0:
            raise doc.fail(speed, f"attribute value: a final speed must be >= 0, got {value:g}")
    else:
        kind, value = doc.choice(speed, "speedTargetValueType", ("delta", "factor")), doc.number(speed, "value")
    if not steady:
        return FinalSpeed(kind, value, line=speed.line)
    if len(steady) > 1:
        raise doc.fail(steady[1], f"may appear once inside <{speed.tag}>")
    state = steady[0]
    if state.tag == "SteadyState":  # OpenSCENARIO 1.1 wrote the choice inside a <SteadyState>
        state = doc.single(state, {"TargetDistanceSteadyState", "TargetTimeSteadyState"})
    doc.children(state, set())
    name = "distance" if state.tag == "TargetDistanceSteadyState" else "time"
    amount = doc.number(state, name)
    if amount < 0:
        raise doc.fail(state, f"attribute {name} must be >= 0, got {amount:g}")
    if name == "distance":
        return FinalSpeed(kind, value, steady_m=amount, line=state.line)
    return FinalSpeed(kind, value, steady_s=amount, line=state.line)


def read_longitudinal_distance(
    doc: XoscDocument, action: Element, entity: str, condition: Condition, event: str
) -> Placement:
    """The `<LongitudinalDistanceAction>` inside LongitudinalAction `action` of entity `entity`, as a placement."""
    distance = doc.single(action, {"LongitudinalDistanceAction"})
    doc.children(distance, {"DynamicConstraints"})
    if doc.choice(distance, "continuous", ("false", "true", "0", "1")) in ("true", "1"):
        raise doc.fail(
            distance,
            "continuous true is not supported: vrusim's VRUs and obstacles do not follow the ego "
            "(only a placement at t = 0, continuous false)",
        )
    constraints = distance.first("DynamicConstraints")
    if constraints is not None:
        raise doc.fail(
            constraints, "is not supported: vrusim places the entity at once (no approach under dynamic limits)"
        )
    if event and (condition.kind, condition.value) != ("time", 0.0):
        raise doc.fail(distance, "is only supported in <Init> or an event started at simulation time 0")
    doc.choice(distance, "coordinateSystem", ("entity",), "entity")
    given = [name for name in ("distance", "timeGap") if name in distance.attrib]
    if len(given) != 1:
        raise doc.fail(distance, "needs exactly one of the attributes distance and timeGap")
    value = doc.number(distance, given[0])
    if value < 0:
        raise doc.fail(distance, f"attribute {given[0]} must be >= 0, got {value:g}")
    freespace = doc.choice(distance, "freespace", ("false", "true", "0", "1")) in ("true", "1")
    displacement = doc.choice(distance, "displacement", tuple(DISPLACEMENTS), "trailingReferencedEntity")
    return Placement(
        entity=entity,
        master=doc.text(distance, "entityRef"),
        distance_m=value if given[0] == "distance" else None,
        time_gap_s=value if given[0] == "timeGap" else None,
        freespace=freespace,
        displacement=DISPLACEMENTS[displacement],
        line=distance.line,
    )
