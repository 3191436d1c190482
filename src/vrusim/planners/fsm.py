"""The paper's rule-based finite-state collision-avoidance planner (CAP), vectorised over the batch.

States: Cruise → Pre-Slow → Emergency-Brake → back to Cruise (He et al., CPSI 2025, Fig. 5), plus Follow for a
VRU riding ahead in the ego's lane (the paper's "stable following state" of the e-scooter case).

- Cruise: no conflicting VRU; track the cruise speed, a = k_v (v_cruise - v), within [-pre_slow, cruise_accel].
- Pre-Slow: the nearest conflicting VRU is farther than D_safe = headway * v (two-second rule, headway 2 s);
  gentle constant deceleration.
- Emergency-Brake: it is within D_safe; full emergency deceleration, held until the VRU has cleared the path
  (no conflicting VRU left), then Cruise.
- A crossing VRU starts a slow-down only when its corridor window overlaps the ego's own occupancy of the
  conflict zone at the current speed (floored at `arrival_min_speed_mps`), widened by `time_margin_s`: a VRU
  that will have crossed before the ego arrives does not slow it down. Once slowing (Pre-Slow or
  Emergency-Brake) the ego returns to Cruise only when the VRU has cleared the path, as in the paper.
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
from pydantic import Field

from vrusim.kernels import batch_kernel, njit, prange
from vrusim.planners.base import PlannerBase
from vrusim.planners.conflict import new_tracks, track_and_analyse
from vrusim.planners.params import param_table, validate_params
from vrusim.scenario.strict import StrictModel
from vrusim.sim.compaction import take_members
from vrusim.sim.observation import Observation
from vrusim.sim.params import BatchParams

CRUISE, PRE_SLOW, EMERGENCY_BRAKE, FOLLOW = 0, 1, 2, 3


class FsmParams(StrictModel):
    """Parameters of the FSM planner (YAML `planner.params`)."""

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
    time_margin_s: float = Field(1.0, ge=0, description="gap kept between VRU and ego corridor occupancy, s")
    arrival_min_speed_mps: float = Field(1.0, gt=0, description="speed floor for the ego arrival estimate")


def planner_params(params: BatchParams) -> list[FsmParams]:
    """Validate each variant's planner parameters, naming the offending field on error."""
    return validate_params(FsmParams, params)


class FsmPlanner(PlannerBase):
    """Cruise / Pre-Slow / Emergency-Brake / Follow, per variant (one compiled kernel per step)."""

    mode_names = ("cruise", "pre_slow", "emergency_brake", "follow")

    def reset(self, params: BatchParams) -> None:
        """Read per-variant parameters and start every variant in Cruise."""
        per_variant = planner_params(params)
        self.table = param_table(per_variant, PARAM_ORDER)
        self.zone_length = 2.0 * params.half_length_m + 2.0 * params.half_width_m
        self.mode = np.zeros(params.size, dtype=np.int8)
        self.tracks: np.ndarray | None = None
        self.station: np.ndarray | None = None

    def compact(self, index: np.ndarray) -> None:
        """Keep only variants `index` (the engine drops stopped ones)."""
        take_members(self, index)

    def act(self, obs: Observation) -> np.ndarray:
        """Update each variant's state from the nearest threatening VRU; return its acceleration command."""
        if self.tracks is None:
            self.tracks, self.station = new_tracks(obs)
        command = np.empty(self.mode.shape)
        _fsm_step(
            self.mode.shape[0],
            obs.routes.arrays,
            obs.route_offset,
            obs.t_s,
            obs.ego_station_m + obs.rear_to_front_m,
            obs.ego_speed_mps,
            obs.cruise_speed_mps,
            obs.half_width_m,
            self.zone_length,
            obs.ego_length_m,
            obs.detected,
            obs.vru_estimate,
            obs.vru_radius_m,
            self.table,
            self.tracks,
            self.station,
            self.mode,
            command,
        )
        return command


PARAM_ORDER = (
    "headway_s",
    "pre_slow_decel_mps2",
    "emergency_decel_mps2",
    "cruise_accel_mps2",
    "cruise_gain_per_s",
    "follow_headway_s",
    "follow_decel_mps2",
    "follow_comfort_decel_mps2",
    "follow_standstill_gap_m",
    "lead_emergency_ttc_s",
    "conflict_horizon_s",
    "corridor_margin_m",
    "track_memory_s",
    "time_margin_s",
    "arrival_min_speed_mps",
)
(
    _HEADWAY,
    _PRE_SLOW,
    _EMERGENCY,
    _CRUISE_ACCEL,
    _CRUISE_GAIN,
    _FOLLOW_HEADWAY,
    _FOLLOW_DECEL,
    _COMFORT_DECEL,
    _STANDSTILL,
    _LEAD_TTC,
    _HORIZON,
    _MARGIN,
    _MEMORY,
    _TIME_MARGIN,
    _ARRIVAL_SPEED,
) = range(len(PARAM_ORDER))


@batch_kernel
def _fsm_step(
    path,
    offsets,
    t,
    front_station,
    speed,
    cruise_speed,
    half_width,
    zone_length,
    ego_length,
    detected,
    estimate,
    radius,
    p,
    tracks,
    station,
    mode,
    command,
):  # pragma: no cover (compiled)
    for b in prange(detected.shape[0]):
        fsm_variant(
            b,
            path,
            offsets,
            t,
            front_station,
            speed,
            cruise_speed,
            half_width,
            zone_length,
            ego_length,
            detected,
            estimate,
            radius,
            p,
            tracks,
            station,
            mode,
            command,
        )


@njit(cache=True, inline="always")
def fsm_variant(
    b,
    path,
    offsets,
    t,
    front_station,
    speed,
    cruise_speed,
    half_width,
    zone_length,
    ego_length,
    detected,
    estimate,
    radius,
    p,
    tracks,
    station,
    mode,
    command,
):  # pragma: no cover (compiled)
    """`_fsm_step` for variant b."""
    K = detected.shape[1]
    v = speed[b]
    arrival_speed = max(v, p[b, _ARRIVAL_SPEED])
    margin = p[b, _TIME_MARGIN]
    braking = mode[b] == PRE_SLOW or mode[b] == EMERGENCY_BRAKE
    gap, lead_speed, is_lead = np.inf, 0.0, False
    for k in range(K):
        known, station[b, k], conflict, lead, distance, along, t_in, t_out = track_and_analyse(
            path,
            offsets[b],
            t,
            detected[b, k],
            estimate,
            b,
            k,
            p[b, _MEMORY],
            tracks[b, k],
            station[b, k],
            front_station[b],
            front_station[b] - ego_length[b],
            half_width[b],
            radius[b, k],
            p[b, _MARGIN],
            p[b, _HORIZON],
            False,  # the distance of a VRU that does not conflict is not read below
        )
        if not known:
            continue
        if not conflict:
            continue
        arrive = distance / arrival_speed
        clear = (distance + zone_length[b] + 2.0 * radius[b, k]) / arrival_speed
        overlap = t_in <= clear + margin and t_out >= arrive - margin
        if (lead or overlap or braking) and distance < gap:
            gap, lead_speed, is_lead = distance, along, lead
    if gap == np.inf:
        mode[b] = CRUISE
    elif is_lead:
        closing = v - lead_speed
        ttc = gap / closing if closing > 1e-6 else np.inf
        mode[b] = EMERGENCY_BRAKE if ttc < p[b, _LEAD_TTC] else FOLLOW
    elif mode[b] == EMERGENCY_BRAKE or gap <= p[b, _HEADWAY] * v:
        mode[b] = EMERGENCY_BRAKE
    else:
        mode[b] = PRE_SLOW
    if mode[b] == CRUISE:
        a = p[b, _CRUISE_GAIN] * (cruise_speed[b] - v)
        command[b] = min(max(a, -p[b, _PRE_SLOW]), p[b, _CRUISE_ACCEL])
    elif mode[b] == PRE_SLOW:
        command[b] = -p[b, _PRE_SLOW]
    elif mode[b] == EMERGENCY_BRAKE:
        command[b] = -p[b, _EMERGENCY]
    else:  # IDM+ toward the lead
        a_max, comfort = p[b, _CRUISE_ACCEL], p[b, _COMFORT_DECEL]
        desired = (
            p[b, _STANDSTILL] + v * p[b, _FOLLOW_HEADWAY] + v * (v - lead_speed) / (2.0 * np.sqrt(a_max * comfort))
        )
        desired = max(desired, p[b, _STANDSTILL])
        free_road = (v / max(cruise_speed[b], 0.1)) ** 4
        interaction = (desired / max(gap, 1e-3)) ** 2
        a = a_max * min(1.0 - free_road, 1.0 - interaction)
        command[b] = min(max(a, -p[b, _FOLLOW_DECEL]), a_max)
