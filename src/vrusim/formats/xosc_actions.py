"""Read the private actions vrusim imports: TeleportAction, SpeedAction (absolute target) and FollowTrajectoryAction
with a polyline.

A speed action is a step (at once), or linear, cubic or sinusoidal at a rate (m/s^2), over a time (s) or over a
distance (m) (shapes: `xosc_speed_shapes`); relative targets are refused. A trajectory is a `<Polyline>` of
positions, a `<Clothoid>` or a `<ClothoidSpline>` (`xosc_clothoid`), inline or a catalog entry (`xosc_catalogs`,
read in the entry's parameter scope), not closed, with or without timing (`xosc_timing`). An AssignRouteAction is
read as the vertices of its route's lanes (`xosc_route_action`). Every other action (lane changes, ...) is refused,
naming the element and its line.
"""

from __future__ import annotations

from collections.abc import Mapping

from vrusim.formats.xml_file import Element
from vrusim.formats.xodr_model import Network
from vrusim.formats.xosc_catalogs import catalog_entry
from vrusim.formats.xosc_clothoid import read_clothoid, read_clothoid_spline
from vrusim.formats.xosc_document import XoscDocument
from vrusim.formats.xosc_model import Ramp, SampledShape, VertexTimes, WorldPose
from vrusim.formats.xosc_positions import read_position
from vrusim.formats.xosc_route_action import assign_route
from vrusim.formats.xosc_timing import read_timing, vertex_times

PRIVATE_ACTIONS = {"TeleportAction", "LongitudinalAction", "RoutingAction", "AppearanceAction", "LightStateAction"}
"""Private actions read (`AppearanceAction` and the OpenSCENARIO 1.0 placement of `LightStateAction`: ignored)."""
NEUTRAL_ACTIONS = {"ControllerAction", "ActivateControllerAction"}
"""Private actions without an effect on the motion when only assigned or activated: ignored with --lenient."""


def teleport(
    doc: XoscDocument, action: Element, network: Network, placed: Mapping[str, WorldPose] | None = None
) -> WorldPose:
    """The pose of a `<TeleportAction>` (relative to an entity of `placed`, the entities placed before it)."""
    return read_position(doc, doc.single(action, {"Position"}), network, placed)


def speed(doc: XoscDocument, action: Element) -> tuple[float, Ramp]:
    """(target speed m/s, dynamics) of a `<LongitudinalAction>` holding a SpeedAction with an absolute target.

    Shapes step, linear, cubic and sinusoidal (dimension rate m/s^2, time s or distance m) are read; which of
    them an entity may use is decided when the scenario is built (`xosc_speed_shapes`).
    """
    speed_action = doc.single(action, {"SpeedAction"})
    doc.children(speed_action, {"SpeedActionDynamics", "SpeedActionTarget"})
    dynamics = doc.child(speed_action, "SpeedActionDynamics")
    doc.children(dynamics, set())
    target = doc.single(doc.child(speed_action, "SpeedActionTarget"), {"AbsoluteTargetSpeed"})
    doc.children(target, set())
    value = doc.number(target, "value")
    shape = doc.choice(dynamics, "dynamicsShape", ("step", "linear", "cubic", "sinusoidal"))
    if shape == "step":
        return value, Ramp("step", "rate", 0.0, dynamics.line)
    dimension = doc.choice(dynamics, "dynamicsDimension", ("rate", "time", "distance"))
    amount = abs(doc.number(dynamics, "value"))
    if dimension == "rate" and amount == 0.0:
        raise doc.fail(dynamics, f"a {shape} speed change needs a rate > 0")
    return value, Ramp(shape, dimension, amount, dynamics.line)


def _shape(
    doc: XoscDocument, trajectory: Element, network: Network, placed: Mapping[str, WorldPose] | None, actor: str
) -> SampledShape:
    doc.children(trajectory, {"ParameterDeclarations", "Shape"})
    doc = doc.scoped(trajectory.first("ParameterDeclarations"))
    if doc.choice(trajectory, "closed", ("false", "true", "0", "1")) in ("true", "1"):
        raise doc.fail(trajectory, "a closed trajectory is not supported")
    shape = doc.single(doc.child(trajectory, "Shape"), {"Polyline", "Clothoid", "ClothoidSpline"})
    own = placed.get(actor) if placed is not None else None
    if shape.tag == "Clothoid":
        return read_clothoid(doc, shape, network, placed, own)
    if shape.tag == "ClothoidSpline":
        return read_clothoid_spline(doc, shape, network, placed, own)
    sampled = SampledShape()
    for vertex in doc.children(shape, {"Vertex"}):
        sampled.vertices.append(read_position(doc, doc.single(vertex, {"Position"}), network, placed))
        sampled.times_s.append(doc.number(vertex, "time") if "time" in vertex.attrib else None)
        sampled.sources.append((vertex.tag, vertex.line))
    if len(sampled.vertices) < 2:
        raise doc.fail(shape, "needs at least two <Vertex>")
    return sampled


def follow_trajectory(
    doc: XoscDocument, action: Element, network: Network, placed: Mapping[str, WorldPose] | None = None, actor: str = ""
) -> tuple[tuple[WorldPose, ...], float, VertexTimes | None]:
    """(vertices, initial distance offset m, vertex times or None) of a `<RoutingAction>` holding a
    FollowTrajectoryAction or an AssignRouteAction; `placed`: the entities placed in `<Init>` (relative positions),
    `actor` the entity it moves."""
    follow = doc.single(action, {"FollowTrajectoryAction", "AssignRouteAction", "AcquirePositionAction"})
    if follow.tag == "AssignRouteAction":
        return tuple(assign_route(doc, follow, network, placed).vertices), 0.0, None
    if follow.tag != "FollowTrajectoryAction":
        raise doc.fail(follow, "is not supported (vrusim imports a FollowTrajectoryAction or an AssignRouteAction)")
    doc.children(
        follow, {"TrajectoryRef", "Trajectory", "CatalogReference", "TimeReference", "TrajectoryFollowingMode"}
    )
    holder = follow.first("TrajectoryRef")
    if holder is not None:
        trajectory = doc.single(holder, {"Trajectory", "CatalogReference"})
    else:
        trajectory = doc.child(follow, "CatalogReference" if follow.first("CatalogReference") else "Trajectory")
    scope = doc
    if trajectory.tag == "CatalogReference":
        entry = catalog_entry(doc, trajectory, ("TrajectoryCatalog",), {"Trajectory"})
        scope, trajectory = entry.doc, entry.element
    timing = read_timing(doc, doc.child(follow, "TimeReference"))
    mode = doc.child(follow, "TrajectoryFollowingMode")
    doc.choice(mode, "followingMode", ("position", "follow"))
    offset = doc.number(follow, "initialDistanceOffset", 0.0)
    shape = _shape(scope, trajectory, network, placed, actor)
    return tuple(shape.vertices), offset, vertex_times(scope, shape, timing)
