"""Read an OpenSCENARIO `<Storyboard>` into a `StoryDef`: each entity's initial pose and speed, its trajectory and
speed changes with their start conditions, the stop conditions and the time of day.

Init: TeleportAction, a step SpeedAction, a FollowTrajectoryAction, and a GlobalAction EnvironmentAction with a
`<TimeOfDay>` (night: before `DAY_STARTS_H` or from `NIGHT_STARTS_H`; also in an event started at t = 0). Story:
acts started at t = 0, maneuver groups of one actor, maneuvers inline or from a catalog (`xosc_catalogs`), events of
private actions (`xosc_actions`), one start trigger each (`xosc_conditions`). Appearance and light actions are
ignored and listed in `ImportNotes`; weather, road conditions and controller assignments too with
`ImportNotes.lenient`, else they are refused.
"""

from __future__ import annotations

from collections.abc import Callable
from datetime import datetime

from vrusim.formats.xml_file import Element, shown
from vrusim.formats.xodr_model import Network
from vrusim.formats.xosc_actions import NEUTRAL_ACTIONS, PRIVATE_ACTIONS, follow_trajectory, speed, teleport
from vrusim.formats.xosc_catalogs import catalog_entry
from vrusim.formats.xosc_conditions import read_trigger
from vrusim.formats.xosc_document import XoscDocument
from vrusim.formats.xosc_model import Condition, Motion, RampedSpeedChange, StoryDef, Trajectory, WorldPose
from vrusim.formats.xosc_notes import ImportNotes
from vrusim.formats.xosc_synchronize import SYNC_ACTIONS, read_longitudinal_distance, read_synchronize
from vrusim.formats.xosc_variables import read_variable_action

DAY_STARTS_H, NIGHT_STARTS_H = 6, 20
"""Hours (local time of day) between which a `<TimeOfDay>` is daylight; outside them it is night."""

AT_START = Condition("time", 0.0)


class _StoryReader:
    def __init__(self, doc: XoscDocument, network: Network, entities: set[str], notes: ImportNotes) -> None:
        self.doc, self.network, self.entities, self.notes = doc, network, entities, notes
        self.story = StoryDef(motions={name: Motion() for name in entities})

    def motion(self, element: Element, name: str) -> Motion:
        if name not in self.entities:
            raise self.doc.fail(element, f"names no entity: {shown(name)}")
        return self.story.motions[name]

    def private(self, element: Element, name: str, condition: Condition, event: str) -> None:
        """One `<PrivateAction>` of entity `name`, started by `condition` (in event `event`; "" for Init)."""
        doc, motion = self.doc, self.motion(element, name)
        action = doc.single(element, PRIVATE_ACTIONS | NEUTRAL_ACTIONS | SYNC_ACTIONS)
        if action.tag in ("AppearanceAction", "LightStateAction"):
            self.notes.ignore(action, "lights and appearance do not change the motion")
        elif action.tag in NEUTRAL_ACTIONS:
            self.controller(action)
        elif action.tag == "TeleportAction":
            if event:
                raise doc.fail(action, "is only supported in <Init>")
            motion.pose = teleport(doc, action, self.network, self.placed())
        elif action.tag == "SynchronizeAction":
            if motion.sync is not None:
                raise doc.fail(action, f"entity {shown(name)} is already synchronised (a VRU synchronises once)")
            motion.sync = read_synchronize(doc, action, self.network, event, condition)
        elif action.tag == "LongitudinalAction" and action.first("LongitudinalDistanceAction") is not None:
            self.story.placements.append(read_longitudinal_distance(doc, action, name, condition, event))
        elif action.tag == "LongitudinalAction":
            target, ramp = speed(doc, action)
            if event:
                rate = ramp.value if ramp.dimension == "rate" and ramp.shape == "linear" else None
                change = RampedSpeedChange(event, target, rate, condition, action.line, ramp=ramp)
                motion.speed_changes.append(change)
            elif ramp.shape != "step":
                raise doc.fail(action, "an initial speed must be a step (dynamicsShape step)")
            else:
                motion.initial_speed_mps = target
        else:
            if motion.trajectory is not None:
                raise doc.fail(action, f"entity {shown(name)} already follows a trajectory")
            vertices, offset, times = follow_trajectory(doc, action, self.network, self.placed(), name)
            motion.trajectory = Trajectory(vertices, offset, condition, action.line, times)

    def placed(self) -> dict[str, WorldPose]:
        """The entities placed so far (by `<Init>` TeleportActions, in file order) and their poses."""
        return {name: motion.pose for name, motion in self.story.motions.items() if motion.pose is not None}

    def controller(self, action: Element) -> None:
        """A controller assignment or activation: no effect on the motion (the ego and VRUs follow the file)."""
        stack = list(action.children)
        while stack:
            inner = stack.pop()
            if inner.tag == "OverrideControllerValueAction":
                raise self.doc.fail(inner, "is not supported: it changes the motion")
            stack.extend(inner.children)
        self.notes.tolerate(self.doc, action, "controllers do not change the motion vrusim imports")

    def environment(self, element: Element, event: str = "") -> None:
        doc = self.doc
        action = doc.single(element, {"EnvironmentAction", "VariableAction", "ParameterAction"})
        if action.tag == "ParameterAction":
            raise doc.fail(action, "is not supported (deprecated in OpenSCENARIO 1.2): use a VariableAction")
        if action.tag == "VariableAction":
            if not event:
                raise doc.fail(
                    action, "is supported only in an event: give the variable's initial value in <VariableDeclarations>"
                )
            self.story.variable_changes.append(read_variable_action(doc, action, event))
            return
        environment = doc.single(action, {"Environment"})
        doc.children(environment, {"ParameterDeclarations", "TimeOfDay", "Weather", "RoadCondition"})
        for child in environment.children:
            if child.tag in ("Weather", "RoadCondition"):
                self.notes.tolerate(doc, child, "vrusim has no weather or road-condition model")
        time_of_day = doc.optional(environment, "TimeOfDay")
        if time_of_day is None:
            return
        text = doc.text(time_of_day, "dateTime")
        try:
            hour = datetime.fromisoformat(text).hour
        except ValueError:
            raise doc.fail(time_of_day, f"attribute dateTime: expected an ISO 8601 time, got {shown(text)}") from None
        self.story.night = not DAY_STARTS_H <= hour < NIGHT_STARTS_H

    def init(self, init: Element) -> None:
        doc = self.doc
        actions = doc.single(init, {"Actions"})
        for element in doc.children(actions, {"GlobalAction", "Private"}):
            if element.tag == "GlobalAction":
                self.environment(element)
                continue
            name = doc.text(element, "entityRef")
            for action in doc.children(element, {"PrivateAction"}):
                self.private(action, name, AT_START, "")

    def event(self, element: Element, actor: str) -> None:
        doc = self.doc
        doc.children(element, {"Action", "StartTrigger"})
        name = doc.text(element, "name")
        condition = read_trigger(doc, doc.child(element, "StartTrigger"), single=True, network=self.network)[0]
        self.story.events[name] = condition
        for action in element.all("Action"):
            inner = doc.single(action, {"PrivateAction", "GlobalAction"})
            if inner.tag == "PrivateAction":
                self.private(inner, actor, condition, name)
            elif inner.first("VariableAction") or inner.first("ParameterAction"):
                self.environment(inner, name)
            elif (condition.kind, condition.value) != ("time", 0.0):
                raise doc.fail(inner, "is only supported in an event started at simulation time 0")
            else:
                self.environment(inner)

    def group(self, element: Element) -> None:
        doc = self.doc
        doc.children(element, {"Actors", "Maneuver", "CatalogReference"})
        actors = doc.children(doc.child(element, "Actors"), {"EntityRef"})
        if len(actors) != 1:
            raise doc.fail(element, "needs exactly one actor (<EntityRef>)")
        actor = doc.text(actors[0], "entityRef")
        for maneuver in element.children:
            if maneuver.tag == "CatalogReference":
                entry = catalog_entry(doc, maneuver, ("ManeuverCatalog",), {"Maneuver"})
                self.doc = entry.doc
                try:
                    self.maneuver(entry.element, actor)
                finally:
                    self.doc = doc
            elif maneuver.tag == "Maneuver":
                self.in_scope(maneuver, lambda m=maneuver: self.maneuver(m, actor))

    def in_scope(self, element: Element, read: Callable[[], object]) -> None:
        """Call `read` with the parameters `element` declares in scope (`XoscDocument.scoped`)."""
        outer = self.doc
        self.doc = outer.scoped(element.first("ParameterDeclarations"))
        try:
            read()
        finally:
            self.doc = outer

    def maneuver(self, maneuver: Element, actor: str) -> None:
        """The events of `<Maneuver>` `maneuver` (inline, or a catalog entry read in its own scope)."""
        self.doc.children(maneuver, {"ParameterDeclarations", "Event"})
        for event in maneuver.all("Event"):
            self.event(event, actor)

    def act(self, element: Element) -> None:
        doc = self.doc
        doc.children(element, {"ManeuverGroup", "StartTrigger", "StopTrigger"})
        start = doc.optional(element, "StartTrigger")
        first = read_trigger(doc, start, single=True)[0] if start is not None else AT_START
        if start is not None and (first.kind, first.value) != ("time", 0.0):
            raise doc.fail(start, "an act must start at simulation time 0")
        stop = doc.optional(element, "StopTrigger")
        if stop is not None and stop.children:
            raise doc.fail(stop, "an act's stop trigger is not supported (the storyboard's stops the run)")
        for group in element.all("ManeuverGroup"):
            self.group(group)

    def storyboard(self, element: Element) -> StoryDef:
        doc = self.doc
        doc.children(element, {"Init", "Story", "StopTrigger"})
        self.init(doc.child(element, "Init"))
        for story in element.all("Story"):
            doc.children(story, {"ParameterDeclarations", "Act"})
            self.in_scope(story, lambda s=story: [self.act(act) for act in s.all("Act")])
        self.story.stop = read_trigger(doc, doc.child(element, "StopTrigger"), single=False, network=self.network)
        return self.story


def read_storyboard(
    doc: XoscDocument, storyboard: Element, network: Network, entities: set[str], notes: ImportNotes | None = None
) -> StoryDef:
    """The storyboard of the file: every entity of `entities` has a `Motion` (empty when the file gives none).
    Ignored elements are listed in `notes`."""
    return _StoryReader(doc, network, entities, notes or ImportNotes()).storyboard(storyboard)
