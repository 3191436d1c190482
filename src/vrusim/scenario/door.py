"""A door of the (parked) ego that opens into a passing VRU's path (`ego.door`, Euro NCAP CBDA dooring).

LSC26 §3.2.3: the driver's door opening interface is operated when the cyclist's front reference point is at the
"door operation distance" from the most rearward point of the driver's door (5.5 / 8 / 11 m at 10 / 15 / 20 km/h,
each with an upper tolerance); §1.2.2.4: the impact location is the rear of the closed driver door. The door's
motion (opening delay, angular speed, end angle) is not given by LSC26 and is this model's choice (UNVERIFIED
defaults). See docs/models.md, "Door".
"""

from __future__ import annotations

from typing import Literal, Self

from pydantic import Field, model_validator

from vrusim.scenario.strict import StrictModel, the_one_given

DOOR_TRIGGERS = ("at_time_s", "vru_distance_m")
"""The conditions the door operation can start on (exactly one)."""


class DoorTrigger(StrictModel):
    """When the occupant operates the door: at a time, or when VRU `vru` is within `vru_distance_m` of the door.

    The distance is measured along the ego's length axis from the front of the VRU's footprint (its centre
    plus its radius toward the door) to the rear edge of the closed door: |x_vru - x_door_rear| - radius.
    """

    at_time_s: float | None = Field(None, ge=0)
    vru_distance_m: float | None = Field(None, ge=0, description="door operation distance (LSC26 §3.2.3), m")
    vru: int = Field(0, ge=0, le=63, description="index of the VRU in `vrus` the distance is measured to")

    @model_validator(mode="after")
    def _exactly_one(self) -> Self:
        the_one_given(self, DOOR_TRIGGERS)
        return self


class Door(StrictModel):
    """A side door: a thin rectangle hinged at its front edge on the body side, `hinge_from_front_m` behind the
    front of the vehicle; it swings outward at `opening_rate_deg_ps` up to `max_angle_deg`, starting
    `delay_s` after its trigger (while a function holds it, "door retention", it does not move)."""

    side: Literal["left", "right"] = Field("left", description="side of the real vehicle (driver's door: left)")
    hinge_from_front_m: float = Field(1.3, ge=0, description="front of the vehicle to the hinge, m")
    length_m: float = Field(1.1, gt=0, description="hinge to the door's rear edge, m")
    thickness_m: float = Field(0.1, gt=0, description="m")
    max_angle_deg: float = Field(60.0, gt=0, le=90, description="fully open angle (UNVERIFIED default)")
    opening_rate_deg_ps: float = Field(60.0, gt=0, description="angular speed while opening (UNVERIFIED default)")
    delay_s: float = Field(0.0, ge=0, description="from the door operation to the door moving, s")
    trigger: DoorTrigger
