"""DOW, door-opening warning with door retention (Euro NCAP LSC26 CBDA, §3.2.3 and §5.2.3), vectorised.

For each tracked VRU alongside the door's side of the (parked) ego, the time to the door is

    TTC_door = (gap along the vehicle's length axis from the front of the VRU's footprint to the rear edge of the
                closed door) / (its speed along that axis)

positive while it approaches, negative once its front has passed the door's rear edge (LSC26 measures the door
operation distance between the same two points). "Alongside" means its centre lies outside the body on the door
side, at most `lateral_band_m` from it. DOW is active while some such VRU has
-`release_after_pass_s` < TTC_door <= `warning_ttc_s`: it warns (`warning`) and, with `retention`, holds the
door closed (`door_hold`, the engine's door retention). LSC26 §5.2.3 scores a retention green when it starts at
TTC >= 1.70 s and ends at TTC <= -0.40 s; the defaults (3.0 s, 0.6 s) leave room for detection and a step.
The ego follows its driver (a parked ego: zero command). Every variant needs an `ego.door`. Modes: idle,
warn, retention.
"""

from __future__ import annotations

import numpy as np
from pydantic import Field

from vrusim.errors import UserInputError
from vrusim.kernels import batch_kernel, prange
from vrusim.planners.base import PlannerBase
from vrusim.planners.conflict import new_tracks, update_track
from vrusim.planners.params import param_table, validate_params
from vrusim.scenario.strict import StrictModel
from vrusim.sim.compaction import take_members
from vrusim.sim.observation import Observation
from vrusim.sim.params import BatchParams

IDLE, WARNING, RETENTION = 0, 1, 2


class DowParams(StrictModel):
    """Parameters of the DOW planner (YAML `planner.params`)."""

    warning_ttc_s: float = Field(3.0, gt=0, description="warn / hold at TTC_door <= this, s (LSC26: >= 1.70 s)")
    release_after_pass_s: float = Field(0.6, ge=0, description="hold until TTC_door <= -this, s (LSC26: >= 0.40)")
    lateral_band_m: float = Field(2.5, gt=0, description="VRU centre at most this far outside the door side, m")
    retention: bool = Field(True, description="hold the door closed while active (false: warning only)")
    min_speed_mps: float = Field(0.3, gt=0, description="slower VRUs are not approaching, m/s")
    track_memory_s: float = Field(1.0, ge=0, description="how long a lost VRU is still considered, s")


PARAM_ORDER = tuple(DowParams.model_fields)
_WARN, _RELEASE, _BAND, _RETENTION, _MIN_SPEED, _MEMORY = range(len(PARAM_ORDER))


class DowPlanner(PlannerBase):
    """Warn and hold the door while a VRU approaches or passes it."""

    mode_names = ("idle", "warn", "retention")  # "warn": a mode "warning" would name the column first_warning_s

    def reset(self, params: BatchParams) -> None:
        """Read per-variant parameters and the door geometry; every variant needs a door."""
        for name, has in zip(params.names, params.door.has, strict=True):
            if not has:
                raise UserInputError(f"{name}: ego.door: planner 'dow' needs a door")
        self.table = param_table(validate_params(DowParams, params), PARAM_ORDER)
        door = params.door
        self.rear_x, self.side = door.rear_x_m, np.sign(door.hinge_y_m)
        self.half_width, self.rear_to_centre = params.half_width_m, params.rear_to_centre_m
        self.mode = np.zeros(params.size, dtype=np.int8)
        self.warning = np.zeros(params.size, dtype=bool)
        self.door_hold = np.zeros(params.size, dtype=bool)
        self.ttc_s = np.full(params.size, np.inf)
        """The smallest TTC_door of an active VRU at the last step, s (inf: none)."""
        self.tracks: np.ndarray | None = None

    def compact(self, index: np.ndarray) -> None:
        """Keep only variants `index` (the engine drops stopped ones)."""
        take_members(self, index)

    def act(self, obs: Observation) -> np.ndarray:
        """Mode, warning and door retention of each variant; the driver's request as the command."""
        if self.tracks is None:
            self.tracks, _ = new_tracks(obs)
        _dow_step(
            self.mode.shape[0], obs.t_s, obs.ego_x_m, obs.ego_y_m, obs.ego_heading_x, obs.ego_heading_y,
            self.rear_to_centre, self.half_width, self.rear_x, self.side, obs.detected, obs.vru_estimate,
            obs.vru_radius_m, self.table, self.tracks, self.mode, self.ttc_s,
        )  # fmt: skip
        self.warning = self.mode >= WARNING
        self.door_hold = self.mode == RETENTION
        has_driver, request = obs.driver_request()
        return np.where(has_driver, request, 0.0)


@batch_kernel
def _dow_step(
    t,
    rear_x_w,
    rear_y_w,
    hx,
    hy,
    rear_to_centre,
    half_width,
    door_rear_x,
    side,
    detected,
    estimate,
    radius,
    p,
    tracks,
    mode,
    ttc_out,
):  # pragma: no cover (compiled)
    B, K = detected.shape
    for b in prange(B):
        cx, cy = rear_x_w[b] + rear_to_centre[b] * hx[b], rear_y_w[b] + rear_to_centre[b] * hy[b]
        active, soonest = False, np.inf
        for k in range(K):
            known, x, y, vx, vy, _, _ = update_track(t, detected[b, k], estimate, b, k, p[b, _MEMORY], tracks[b, k])
            if not known:
                continue
            dx, dy = x - cx, y - cy
            lx, ly = dx * hx[b] + dy * hy[b], dy * hx[b] - dx * hy[b]
            lvx = vx * hx[b] + vy * hy[b]
            outside = side[b] * ly - half_width[b]
            if outside < 0.0 or outside > p[b, _BAND] or abs(lvx) < p[b, _MIN_SPEED]:
                continue
            direction = 1.0 if lvx > 0.0 else -1.0
            ttc = ((door_rear_x[b] - lx) * direction - radius[b, k]) / abs(lvx)
            if -p[b, _RELEASE] < ttc <= p[b, _WARN]:
                active = True
                soonest = min(soonest, ttc)
        ttc_out[b] = soonest
        if not active:
            mode[b] = IDLE
        elif p[b, _RETENTION] > 0.5:
            mode[b] = RETENTION
        else:
            mode[b] = WARNING
