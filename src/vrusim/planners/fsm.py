"""The paper's rule-based finite-state collision-avoidance planner (CAP), vectorised over the batch.

States: Cruise → Pre-Slow → Emergency-Brake → back to Cruise (He et al., CPSI 2025, Fig. 5), plus Follow for a
VRU riding ahead in the ego's lane (the paper's "stable following state" of the e-scooter case).

- Cruise: no conflicting VRU; track the cruise speed, a = k_v (v_cruise - v), within [-pre_slow, cruise_accel].
- Pre-Slow: the nearest conflicting VRU is farther than D_safe = headway * v (two-second rule, headway 2 s);
  gentle constant deceleration.
- Emergency-Brake: it is within D_safe; full emergency deceleration, held until the VRU has cleared the path
  (no conflicting VRU left), then Cruise.
- Follow: the nearest conflict is a lead VRU moving along the ego path; IDM+ (Schakel, van Arem & Netten 2010,
  the Intelligent Driver Model of Treiber et al. 2000 with its equilibrium gap equal to s*) follows it:
  a = a_max min(1 - (v / v_cruise)^4, 1 - (s* / gap)^2) with
  s* = s0 + v T + v (v - v_lead) / (2 sqrt(a_max b)), time gap T = `follow_headway_s` (ACC range of ISO 15622;
  1.2 s keeps a 13.4 m/s lead inside a 20 m sensor), within [-follow_decel, cruise_accel]. Emergency-Brake when
  the time-to-collision to the lead, gap / closing speed, falls below `lead_emergency_ttc_s`.
Conflicts are defined in `vrusim.planners.conflict`.
"""

from __future__ import annotations

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, ValidationError

from vrusim.errors import UserInputError
from vrusim.planners.conflict import ConflictTracker
from vrusim.scenario.loading import field_path
from vrusim.sim.batch import BatchParams
from vrusim.sim.observation import Observation

CRUISE, PRE_SLOW, EMERGENCY_BRAKE, FOLLOW = 0, 1, 2, 3


class FsmParams(BaseModel):
    """Parameters of the FSM planner (YAML `planner.params`)."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    headway_s: float = Field(2.0, gt=0, description="D_safe = headway_s * v (two-second rule)")
    pre_slow_decel_mps2: float = Field(2.0, gt=0)
    emergency_decel_mps2: float = Field(8.0, gt=0)
    cruise_accel_mps2: float = Field(1.5, gt=0)
    cruise_gain_per_s: float = Field(0.8, gt=0)
    follow_headway_s: float = Field(1.2, gt=0, description="time gap kept behind a lead VRU, s")
    follow_decel_mps2: float = Field(3.0, gt=0)
    follow_comfort_decel_mps2: float = Field(2.0, gt=0, description="IDM comfortable deceleration b")
    follow_standstill_gap_m: float = Field(2.0, ge=0, description="IDM minimum gap s0")
    lead_emergency_ttc_s: float = Field(1.5, ge=0)
    conflict_horizon_s: float = Field(5.0, gt=0)
    corridor_margin_m: float = Field(0.25, ge=0)
    track_memory_s: float = Field(1.0, ge=0, description="how long a lost VRU is still considered, s")


def planner_params(params: BatchParams) -> list[FsmParams]:
    """Validate each variant's planner parameters, naming the offending field on error."""
    out = []
    for scenario in params.scenarios:
        try:
            out.append(FsmParams.model_validate(scenario.planner.params))
        except ValidationError as error:
            item = error.errors(include_url=False)[0]
            where = field_path(("planner", "params", *item["loc"]))
            message = "unknown field" if item["type"] == "extra_forbidden" else item["msg"]
            raise UserInputError(f"{scenario.name}: {where}: {message}") from None
    return out


class FsmPlanner:
    """Cruise / Pre-Slow / Emergency-Brake / Follow, per variant."""

    mode_names = ("cruise", "pre_slow", "emergency_brake", "follow")

    def reset(self, params: BatchParams) -> None:
        """Read per-variant parameters and start every variant in Cruise."""
        per_variant = planner_params(params)

        def column(name: str) -> np.ndarray:
            return np.array([getattr(p, name) for p in per_variant])

        self.headway = column("headway_s")
        self.pre_slow = column("pre_slow_decel_mps2")
        self.emergency = column("emergency_decel_mps2")
        self.cruise_accel = column("cruise_accel_mps2")
        self.cruise_gain = column("cruise_gain_per_s")
        self.follow_headway = column("follow_headway_s")
        self.follow_decel = column("follow_decel_mps2")
        self.comfort_decel = column("follow_comfort_decel_mps2")
        self.standstill_gap = column("follow_standstill_gap_m")
        self.lead_ttc = column("lead_emergency_ttc_s")
        self.conflicts = ConflictTracker(
            column("conflict_horizon_s"), column("corridor_margin_m"), column("track_memory_s")
        )
        self.mode = np.zeros(params.size, dtype=np.int8)

    def act(self, obs: Observation) -> np.ndarray:
        """Update each variant's state from the nearest conflicting VRU; return its acceleration command."""
        facts = self.conflicts.analyse(obs)
        distance = np.where(facts.conflict, facts.distance_m, np.inf)
        nearest = np.argmin(distance, axis=1)[:, None]
        gap = np.take_along_axis(distance, nearest, axis=1)[:, 0]
        any_conflict = np.isfinite(gap)
        is_lead = np.take_along_axis(facts.lead, nearest, axis=1)[:, 0]
        lead_speed = np.take_along_axis(facts.along_speed_mps, nearest, axis=1)[:, 0]

        speed = obs.ego_speed_mps
        safe_distance = self.headway * speed
        closing = speed - lead_speed
        with np.errstate(divide="ignore", invalid="ignore"):
            lead_ttc = np.where(closing > 1e-6, gap / closing, np.inf)
        braking = self.mode == EMERGENCY_BRAKE
        crossing_mode = np.where(braking | (gap <= safe_distance), EMERGENCY_BRAKE, PRE_SLOW)
        lead_mode = np.where(lead_ttc < self.lead_ttc, EMERGENCY_BRAKE, FOLLOW)
        self.mode = np.where(any_conflict, np.where(is_lead, lead_mode, crossing_mode), CRUISE).astype(np.int8)

        cruise = np.clip(self.cruise_gain * (obs.cruise_speed_mps - speed), -self.pre_slow, self.cruise_accel)
        desired_gap = self.standstill_gap + speed * self.follow_headway + speed * closing / (
            2.0 * np.sqrt(self.cruise_accel * self.comfort_decel)
        )
        desired_gap = np.maximum(desired_gap, self.standstill_gap)
        with np.errstate(divide="ignore"):
            interaction = (desired_gap / np.maximum(gap, 1e-3)) ** 2
        free_road = (speed / np.maximum(obs.cruise_speed_mps, 0.1)) ** 4
        follow = self.cruise_accel * np.minimum(1.0 - free_road, 1.0 - interaction)
        follow = np.clip(follow, -self.follow_decel, self.cruise_accel)
        mode = self.mode
        return np.where(
            mode == CRUISE, cruise,
            np.where(mode == PRE_SLOW, -self.pre_slow, np.where(mode == EMERGENCY_BRAKE, -self.emergency, follow)),
        )
