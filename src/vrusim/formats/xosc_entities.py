"""Read `<Entities>` of an OpenSCENARIO file: vehicles, pedestrians and misc objects with their boxes.

A vehicle's box centre lies `Center x` ahead of its reference point (the rear axle for cars); its wheelbase is
the front axle's `positionX` less the rear axle's, its steering limit the front axle's `maxSteering` (rad).
An entity may be a `<CatalogReference>` to a vehicle, pedestrian or misc object catalog entry (`xosc_catalogs`),
read in the entry's parameter scope. External object references, controllers and entity selections are refused.
"""

from __future__ import annotations

from vrusim.formats.xml_file import Element, shown
from vrusim.formats.xosc_catalogs import ENTITY_LOCATIONS, catalog_entry
from vrusim.formats.xosc_document import XoscDocument
from vrusim.formats.xosc_model import EntityDef

_OBJECT_KINDS = {"Vehicle": "vehicle", "Pedestrian": "pedestrian", "MiscObject": "misc"}
_CATEGORY_ATTRIBUTE = {
    "Vehicle": "vehicleCategory",
    "Pedestrian": "pedestrianCategory",
    "MiscObject": "miscObjectCategory",
}
_ENTITY_CHILDREN = {
    "Vehicle": {"ParameterDeclarations", "BoundingBox", "Performance", "Axles", "Properties"},
    "Pedestrian": {"ParameterDeclarations", "BoundingBox", "Properties"},
    "MiscObject": {"ParameterDeclarations", "BoundingBox", "Properties"},
}


def _box(doc: XoscDocument, entity: Element) -> tuple[float, float, float]:
    """(length m, width m, centre x m) of the entity's `<BoundingBox>`."""
    box = doc.child(entity, "BoundingBox")
    doc.children(box, {"Center", "Dimensions"})
    centre, dimensions = doc.child(box, "Center"), doc.child(box, "Dimensions")
    length, width = doc.number(dimensions, "length"), doc.number(dimensions, "width")
    if length <= 0 or width <= 0:
        raise doc.fail(dimensions, "length and width must be > 0")
    return length, width, doc.number(centre, "x")


def _vehicle_fields(doc: XoscDocument, vehicle: Element) -> dict[str, float]:
    """Wheelbase (m), steering limit (rad) and acceleration limits (m/s^2) of a `<Vehicle>`."""
    axles = doc.child(vehicle, "Axles")
    doc.children(axles, {"FrontAxle", "RearAxle", "AdditionalAxle"})
    if axles.first("AdditionalAxle") is not None:
        raise doc.unsupported(axles.all("AdditionalAxle")[0], "Axles")
    front, rear = doc.child(axles, "FrontAxle"), doc.child(axles, "RearAxle")
    performance = doc.child(vehicle, "Performance")
    doc.children(performance, set())
    return {
        "wheelbase_m": doc.number(front, "positionX") - doc.number(rear, "positionX"),
        "max_steer_rad": doc.number(front, "maxSteering"),
        "max_accel_mps2": doc.number(performance, "maxAcceleration"),
        "max_decel_mps2": doc.number(performance, "maxDeceleration"),
    }


def _entity(doc: XoscDocument, scenario_object: Element) -> EntityDef:
    name = doc.raw(scenario_object, "name")
    objects = set(_OBJECT_KINDS) | {"CatalogReference", "ExternalObjectReference", "ObjectController"}
    doc.children(scenario_object, objects)
    for child in scenario_object.children:
        if child.tag not in _OBJECT_KINDS and child.tag != "CatalogReference":
            raise doc.fail(child, f"(<{child.tag}> of entity {shown(name)}) is not supported; write the entity inline")
    element = doc.single(scenario_object, set(_OBJECT_KINDS) | {"CatalogReference"})
    line = element.line
    if element.tag == "CatalogReference":
        entry = catalog_entry(doc, element, ENTITY_LOCATIONS, set(_OBJECT_KINDS))
        doc, element = entry.doc, entry.element
    doc.children(element, _ENTITY_CHILDREN[element.tag])
    doc = doc.scoped(element.first("ParameterDeclarations"))
    length, width, centre_x = _box(doc, element)
    extra = _vehicle_fields(doc, element) if element.tag == "Vehicle" else {}
    return EntityDef(
        name=name,
        kind=_OBJECT_KINDS[element.tag],
        category=doc.text(element, _CATEGORY_ATTRIBUTE[element.tag]),
        length_m=length,
        width_m=width,
        centre_x_m=centre_x,
        line=line,
        properties=doc.properties(element),
        **extra,
    )


def read_entities(doc: XoscDocument, entities: Element) -> list[EntityDef]:
    """Every `<ScenarioObject>` in document order; duplicate names are an error."""
    doc.children(entities, {"ScenarioObject"})
    found: list[EntityDef] = []
    for scenario_object in entities.children:
        entity = _entity(doc, scenario_object)
        if any(other.name == entity.name for other in found):
            raise doc.fail(scenario_object, f"entity name {shown(entity.name)} is used twice")
        found.append(entity)
    if not found:
        raise doc.fail(entities, "has no <ScenarioObject>")
    return found
