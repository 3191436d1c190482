"""Apply `<LongitudinalDistanceAction>`s at t = 0 (`continuous` false): place an entity relative to another.

The entity is put `distance` (or `timeGap` x the referenced entity's initial speed) ahead of it
(`leadingReferencedEntity`) or behind it (`trailingReferencedEntity`; `any`: on the side where it stands) along
the referenced entity's heading (coordinate system `entity`), keeping its lateral offset and heading from its own
TeleportAction (without one: on the referenced entity's axis, facing its heading). `freespace` false: between the
reference points; true: between the bounding boxes along that heading (the placed box projected onto it).
Placements are applied in file order, before the scenario is built.
"""

from __future__ import annotations

import math
from collections.abc import Callable

from vrusim.errors import UserInputError
from vrusim.formats.xosc_model import EntityDef, Placement, StoryDef, WorldPose

Fail = Callable[[int, str], UserInputError]
_TAG = "<LongitudinalDistanceAction>"


def place_entities(fail: Fail, entities: list[EntityDef], story: StoryDef) -> None:
    """Set the pose of every entity placed by a LongitudinalDistanceAction (in `story.motions`, in place)."""
    by_name = {entity.name: entity for entity in entities}
    for placement in story.placements:
        master = by_name.get(placement.master)
        if master is None:
            raise fail(placement.line, f"{_TAG} entityRef names no entity: {placement.master[:40]!r}")
        if placement.master == placement.entity:
            raise fail(placement.line, f"{_TAG} entity {placement.entity!r} cannot keep a distance to itself")
        master_pose = story.motions[master.name].pose
        if master_pose is None:
            raise fail(placement.line, f"{_TAG} the referenced entity {master.name!r} has no TeleportAction in <Init>")
        motion = story.motions[placement.entity]
        motion.pose = _placed(fail, placement, by_name[placement.entity], motion.pose, master, master_pose, story)


def _placed(
    fail: Fail,
    placement: Placement,
    actor: EntityDef,
    pose: WorldPose | None,
    master: EntityDef,
    master_pose: WorldPose,
    story: StoryDef,
) -> WorldPose:
    ux, uy = math.cos(master_pose.heading_rad), math.sin(master_pose.heading_rad)
    if placement.distance_m is not None:
        gap = placement.distance_m
    else:
        gap = (placement.time_gap_s or 0.0) * abs(story.motions[master.name].initial_speed_mps or 0.0)
    if pose is None:
        lateral, heading, along_now = 0.0, master_pose.heading_rad, None
    else:
        dx, dy = pose.x_m - master_pose.x_m, pose.y_m - master_pose.y_m
        lateral, heading, along_now = -uy * dx + ux * dy, pose.heading_rad, ux * dx + uy * dy
    side = {"leading": 1.0, "trailing": -1.0}.get(placement.displacement)
    if side is None:
        if along_now is None or abs(along_now) < 1e-9:
            raise fail(
                placement.line,
                f"{_TAG} displacement any needs entity {actor.name!r} placed ahead of or behind "
                f"{master.name!r} first (a TeleportAction before it)",
            )
        side = math.copysign(1.0, along_now)
    along = side * gap
    if placement.freespace:
        turn = heading - master_pose.heading_rad
        half = abs(math.cos(turn)) * actor.length_m / 2 + abs(math.sin(turn)) * actor.width_m / 2
        edge = master.centre_x_m + side * master.length_m / 2
        along = edge + side * (gap + half) - actor.centre_x_m * math.cos(turn)
    return WorldPose(master_pose.x_m + along * ux - lateral * uy, master_pose.y_m + along * uy + lateral * ux, heading)
