"""A TTC-based automatic emergency brake (AEB) with forward-collision warning (FCW), vectorised over the batch.

The ego holds its cruise speed. Every step it computes, for every tracked VRU, the time to collision along its
route (`vrusim.planners.route_ttc`: the ego's rectangle driven on along its route at constant speed, the VRU's
circle at constant velocity) and acts on the smallest, in stages as production AEB systems tested by Euro NCAP do:

    TTC <= warning_ttc_s   warning        FCW on (`warning`), no braking
    TTC <= partial_ttc_s   partial_brake  -partial_decel_mps2 (and FCW)
    TTC <= full_ttc_s      full_brake     -full_decel_mps2 (and FCW)

A stage is entered as soon as its threshold is reached. It is left only when the threat has cleared: when the
TTC the ego would have on resuming its cruise speed (the higher of cruise and current speed) exceeds the stage's
threshold plus `hysteresis_s`, or is infinite because the VRU has left the path. Braking is therefore held while
a VRU is still in the path, through to a standstill if need be, and the ego resumes cruise once it has gone.

With a driver schedule (`ego.driver`) "cruise" means following the driver's request; the braking stages override
it. A reversing ego is simulated mirrored (its leading edge is the real rear bumper), so the same stages brake
for VRUs behind it: `reverse_aeb` (`planners/reverse_aeb.py`) is this planner for reversing egos.
"""

from __future__ import annotations

import math

import numpy as np
from pydantic import Field, ValidationInfo, field_validator

from vrusim.kernels import batch_kernel, njit, prange
from vrusim.planners.base import PlannerBase
from vrusim.planners.conflict import new_tracks, update_track
from vrusim.planners.params import param_table, validate_params
from vrusim.planners.route_ttc import route_ttc
from vrusim.scenario.strict import StrictModel
from vrusim.sim.compaction import take_members
from vrusim.sim.observation import Observation
from vrusim.sim.params import BatchParams

CRUISE, WARNING, PARTIAL_BRAKE, FULL_BRAKE = 0, 1, 2, 3


class AebParams(StrictModel):
    """Parameters of the AEB planner (YAML `planner.params`)."""

    warning_ttc_s: float = Field(2.6, gt=0, description="FCW at TTC <= this, s")
    partial_ttc_s: float = Field(1.6, gt=0, description="partial braking at TTC <= this, s")
    full_ttc_s: float = Field(0.9, gt=0, description="full braking at TTC <= this, s")
    partial_decel_mps2: float = Field(4.0, gt=0)
    full_decel_mps2: float = Field(9.0, gt=0)
    hysteresis_s: float = Field(0.5, ge=0, description="a stage is left when TTC > its threshold + this, s")
    cruise_accel_mps2: float = Field(1.5, gt=0)
    cruise_decel_mps2: float = Field(2.0, gt=0, description="lower bound of the cruise speed-keeping command")
    cruise_gain_per_s: float = Field(0.8, gt=0)
    track_memory_s: float = Field(1.0, ge=0, description="how long a lost VRU is still considered, s")
    predict_braking: bool = Field(True, description="a VRU that decelerates is predicted to brake to a stop")

    @field_validator("partial_ttc_s")
    @classmethod
    def _partial_below_warning(cls, value: float, info: ValidationInfo) -> float:
        warning = info.data.get("warning_ttc_s")
        if warning is not None and value > warning:
            raise ValueError(f"must be at most warning_ttc_s ({warning})")
        return value

    @field_validator("full_ttc_s")
    @classmethod
    def _full_below_partial(cls, value: float, info: ValidationInfo) -> float:
        partial = info.data.get("partial_ttc_s")
        if partial is not None and value > partial:
            raise ValueError(f"must be at most partial_ttc_s ({partial})")
        return value

    @field_validator("full_decel_mps2")
    @classmethod
    def _full_above_partial(cls, value: float, info: ValidationInfo) -> float:
        partial = info.data.get("partial_decel_mps2")
        if partial is not None and value < partial:
            raise ValueError(f"must be at least partial_decel_mps2 ({partial})")
        return value


PARAM_ORDER = tuple(AebParams.model_fields)
(
    _WARN_TTC,
    _PARTIAL_TTC,
    _FULL_TTC,
    _PARTIAL_DECEL,
    _FULL_DECEL,
    _HYSTERESIS,
    _CRUISE_ACCEL,
    _CRUISE_DECEL,
    _CRUISE_GAIN,
    _MEMORY,
    _PREDICT_BRAKING,
) = range(len(PARAM_ORDER))


class AebPlanner(PlannerBase):
    """Cruise / warning / partial brake / full brake on the smallest route TTC, per variant."""

    mode_names = ("cruise", "warning", "partial_brake", "full_brake")
    params_model: type[AebParams] = AebParams
    """The parameter model (a subclass with other defaults keeps the fields and their order)."""

    def reset(self, params: BatchParams) -> None:
        """Read per-variant parameters; every variant starts in cruise with the warning off."""
        self.table = param_table(validate_params(self.params_model, params), PARAM_ORDER)
        self.half_length, self.rear_to_centre = params.half_length_m, params.rear_to_centre_m
        self.mode = np.zeros(params.size, dtype=np.int8)
        self.ttc_s = np.full(params.size, np.inf)
        """The smallest route TTC of the last step, s (inf: no threat)."""
        self.tracks: np.ndarray | None = None

    @property
    def warning(self) -> np.ndarray:  # type: ignore[override]
        """FCW per variant, bool [B]: on in every stage from `warning` up (derived from `mode`, so it is current
        after any step, per step or compiled)."""
        return self.mode >= WARNING

    def compact(self, index: np.ndarray) -> None:
        """Keep only variants `index` (the engine drops stopped ones)."""
        take_members(self, index)

    def act(self, obs: Observation) -> np.ndarray:
        """Stage each variant from its smallest TTC; return the acceleration command."""
        if self.tracks is None:
            self.tracks, _ = new_tracks(obs)
        command = np.empty(self.mode.shape)
        has_driver, driver_accel = obs.driver_request()
        _aeb_step(
            self.mode.shape[0],
            obs.routes.arrays,
            obs.route_offset,
            obs.t_s,
            obs.ego_station_m,
            self.rear_to_centre,
            obs.ego_speed_mps,
            obs.cruise_speed_mps,
            self.half_length,
            obs.half_width_m,
            obs.detected,
            obs.vru_estimate,
            obs.vru_radius_m,
            self.table,
            self.tracks,
            self.mode,
            self.ttc_s,
            has_driver,
            driver_accel,
            command,
        )
        return command


@njit(cache=True, inline="always")
def braking_decel(vx, vy, ax, ay):  # pragma: no cover (compiled)
    """Deceleration along the VRU's velocity, m/s^2 (0 when it is not slowing down or stands still)."""
    speed = math.sqrt(vx * vx + vy * vy)
    if speed <= 0.0:
        return 0.0
    return max(-(ax * vx + ay * vy) / speed, 0.0)


@njit(cache=True, inline="always")
def stage_of(ttc, p):  # pragma: no cover (compiled)
    """The stage a TTC (s) calls for under parameter row `p`."""
    if ttc <= p[_FULL_TTC]:
        return FULL_BRAKE
    if ttc <= p[_PARTIAL_TTC]:
        return PARTIAL_BRAKE
    if ttc <= p[_WARN_TTC]:
        return WARNING
    return CRUISE


@batch_kernel
def _aeb_step(
    path,
    offsets,
    t,
    rear_station,
    rear_to_centre,
    speed,
    cruise_speed,
    half_length,
    half_width,
    detected,
    estimate,
    radius,
    p,
    tracks,
    mode,
    ttc_out,
    has_driver,
    driver_accel,
    command,
):  # pragma: no cover (compiled)
    for b in prange(detected.shape[0]):
        aeb_variant(
            b,
            path,
            offsets,
            t,
            rear_station,
            rear_to_centre,
            speed,
            cruise_speed,
            half_length,
            half_width,
            detected,
            estimate,
            radius,
            p,
            tracks,
            mode,
            ttc_out,
            has_driver,
            driver_accel,
            command,
        )


@njit(cache=True, inline="always")
def aeb_variant(
    b,
    path,
    offsets,
    t,
    rear_station,
    rear_to_centre,
    speed,
    cruise_speed,
    half_length,
    half_width,
    detected,
    estimate,
    radius,
    p,
    tracks,
    mode,
    ttc_out,
    has_driver,
    driver_accel,
    command,
):  # pragma: no cover (compiled)
    """`_aeb_step` for variant b."""
    K = detected.shape[1]
    v = speed[b]
    resume = max(v, cruise_speed[b])
    horizon = p[b, _WARN_TTC] + p[b, _HYSTERESIS]  # longer TTCs call for no stage
    ttc, ttc_resume = np.inf, np.inf
    for k in range(K):
        known, x, y, vx, vy, ax, ay = update_track(t, detected[b, k], estimate, b, k, p[b, _MEMORY], tracks[b, k])
        if not known:
            continue
        decel = braking_decel(vx, vy, ax, ay) if p[b, _PREDICT_BRAKING] > 0.5 else 0.0
        ttc = min(
            ttc,
            route_ttc(
                path, offsets[b], rear_station[b], v, rear_to_centre[b], half_length[b], half_width[b],
                x, y, vx, vy, decel, radius[b, k], horizon,
            ),
        )  # fmt: skip
        if mode[b] != CRUISE and resume > v:
            ttc_resume = min(
                ttc_resume,
                route_ttc(
                    path, offsets[b], rear_station[b], resume, rear_to_centre[b], half_length[b], half_width[b],
                    x, y, vx, vy, decel, radius[b, k], horizon,
                ),
            )  # fmt: skip
    ttc_resume = min(ttc_resume, ttc)
    previous = mode[b]
    stage = stage_of(ttc, p[b])
    # escalate at once; keep a stage until resuming cruise would not call for it (hysteresis included)
    stage = max(stage, min(previous, stage_of(ttc_resume - p[b, _HYSTERESIS], p[b])))
    mode[b] = stage
    ttc_out[b] = ttc
    if stage == FULL_BRAKE:
        command[b] = -p[b, _FULL_DECEL]
    elif stage == PARTIAL_BRAKE:
        command[b] = -p[b, _PARTIAL_DECEL]
    elif has_driver[b]:
        command[b] = driver_accel[b]
    else:
        a = p[b, _CRUISE_GAIN] * (cruise_speed[b] - v)
        command[b] = min(max(a, -p[b, _CRUISE_DECEL]), p[b, _CRUISE_ACCEL])
