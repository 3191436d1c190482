"""The driver's longitudinal request (`ego.driver`): a schedule of pedal phases, scenario data in SI units.

Euro NCAP LSC26 (Low Speed Collisions v1.1, Oct 2025) tests drive the VUT by its pedals, not by a target speed:
held at standstill by the brake until T0, then the accelerator-pedal profile of Technical Bulletin CA 102 (SfS,
§3.1, §3.2.1.1, §3.2.2.1); creeping at idle and then a sudden full accelerator input at T_ACC (CPMFC, §3.2.2.3);
reversing to a steady 4 or 8 km/h (CPMRCs, §3.2.2.2). The planner sees the request (`Observation.driver_*`) and
may override it (docs/low_speed_situations.md). See docs/models.md, "Driver".
"""

from __future__ import annotations

from typing import Self

from pydantic import Field, model_validator

from vrusim.scenario.strict import StrictModel, the_one_given

PHASE_STARTS = ("at_time_s", "ego_route_m")
"""The conditions a driver phase can start on (exactly one per phase)."""


class DriverPhase(StrictModel):
    """From its start on, the driver requests `accel_mps2` toward `target_speed_mps` (decelerating at the same
    rate when above it) and then holds that speed. `accelerator`: the accelerator pedal is pressed (what ACPE
    watches); false for idle creeping or braking."""

    at_time_s: float | None = Field(None, ge=0, description="starts at this time, s")
    ego_route_m: float | None = Field(None, ge=0, description="starts when the ego has travelled this far, m")
    target_speed_mps: float = Field(ge=0)
    accel_mps2: float = Field(gt=0, description="rate toward the target speed, m/s^2")
    accelerator: bool = Field(True, description="accelerator pedal pressed in this phase (false: idle or brake)")

    @model_validator(mode="after")
    def _one_start(self) -> Self:
        the_one_given(self, PHASE_STARTS)
        return self


class Driver(StrictModel):
    """The driver's pedal schedule. Before the first phase starts the brake holds the ego (request toward 0 at
    `ego.max_decel_mps2`). Phases start in order: a phase's condition is judged only once the previous one runs.

    `creep_speed_mps` is the Maximum Creeping Speed (LSC26 Definitions): the speed the powertrain reaches at idle
    with no pedal; `idle` is what the driver's request becomes when a function (ACPE) cuts the accelerator.
    """

    phases: list[DriverPhase] = Field(min_length=1, max_length=8)
    creep_speed_mps: float = Field(0.0, ge=0, description="maximum creeping speed at idle, m/s; 0: no creep mode")
    creep_accel_mps2: float = Field(1.0, gt=0, description="idle rate toward the creep speed, m/s^2 (UNVERIFIED)")

    @model_validator(mode="after")
    def _in_order(self) -> Self:
        for kind in PHASE_STARTS:
            values = [getattr(p, kind) for p in self.phases if getattr(p, kind) is not None]
            if values != sorted(values):
                raise ValueError(f"phases: {kind} must not decrease from one phase to the next")
        return self
