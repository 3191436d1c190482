"""A predictive planner: yield to each VRU with the gentlest constant deceleration that lets it clear first.

Every step, for each tracked VRU (track memory as in `vrusim.planners.conflict`):

1. Predict it over `horizon_s` and find where and when it occupies the ego's route corridor
   (`vrusim.planners.prediction`): occupancy points (tau, D, F) along the route.
2. **Pass or yield.** If the ego, at its current speed, clears every occupancy point at least `time_margin_s`
   before the VRU gets there, it passes first and ignores the VRU. Otherwise it yields, and keeps yielding to
   that VRU until the VRU no longer occupies the corridor within the horizon.
3. **Plan.** The ego must reach each occupancy point only `time_margin_s` after the VRU (`follow_time_gap_s`
   behind a VRU riding ahead along the route) and at least `stop_gap_m` short of its near edge. The smallest
   admissible constant acceleration over all points of all yielded-to VRUs, `a_plan`, is the gentlest
   deceleration that lets every VRU clear the zone first, or that stops the ego before the zone when that is
   the only way.
4. **Command.** `min(cruise command, a_plan)`, ramped at `comfort_jerk_mps3`, braking at most
   `comfort_decel_mps2`. A plan that needs more is carried out as an emergency brake (ramped at
   `emergency_jerk_mps3`, at most `emergency_decel_mps2`) until it needs less than `EMERGENCY_EXIT` times the
   comfort limit. When the TTC along the route falls to `emergency_ttc_s` the ego brakes at
   `emergency_decel_mps2` at once.
"""

from __future__ import annotations

from typing import ClassVar, Literal

import numpy as np
from pydantic import Field, ValidationInfo, field_validator

from vrusim.kernels import batch_kernel, njit, prange
from vrusim.planners.base import PlannerBase
from vrusim.planners.conflict import analyse_vru, new_tracks, update_track, warm_station
from vrusim.planners.params import param_table, validate_params
from vrusim.planners.prediction import CONSTANT_VELOCITY, PATH, occupancy_bounds, path_station_of, plan_start
from vrusim.planners.route_ttc import route_ttc
from vrusim.scenario.strict import StrictModel
from vrusim.sim.compaction import take_members
from vrusim.sim.observation import Observation
from vrusim.sim.params import BatchParams

CRUISE, YIELD, FOLLOW, STOP, EMERGENCY_BRAKE = 0, 1, 2, 3, 4
STANDSTILL_MPS = 0.01
"""At or below this speed the ego counts as stopped, m/s."""
ENTRY_HORIZON_S = 60.0
"""Cap on the time to a VRU's predicted corridor entry used in the lead test, s (keeps it finite)."""
EMERGENCY_MIN_SPEED_MPS = 1.0
"""Below this speed a plan beyond the comfort limit is stopping precision, not an emergency, m/s."""
MOVE_OFF_MPS2 = 0.5
"""A stopped ego moves off once the plan allows at least this acceleration (or nothing is left to yield to), m/s^2."""
EMERGENCY_EXIT = 0.8
"""An emergency brake ends when the plan needs less than this fraction of the comfort deceleration."""


class PredictiveParams(StrictModel):
    """Parameters of the predictive planner (YAML `planner.params`)."""

    prediction: Literal["constant_velocity", "path"] = "constant_velocity"
    speed_envelope: bool = Field(True, description="also predict at the VRU's current along-track acceleration")
    horizon_s: float = Field(5.0, gt=0, le=30)
    step_s: float = Field(
        0.1, ge=0.001, le=1, description="prediction sampling step, s: horizon_s / step_s + 1 samples per VRU a step"
    )
    time_margin_s: float = Field(0.5, ge=0, description="ego reaches a zone this long after the VRU left it, s")
    follow_time_gap_s: float = Field(1.0, ge=0, description="time gap behind a VRU riding ahead, s")
    stop_gap_m: float = Field(2.0, ge=0, description="distance kept to a VRU's near edge, m")
    comfort_decel_mps2: float = Field(3.0, gt=0)
    comfort_jerk_mps3: float = Field(2.5, gt=0)
    emergency_decel_mps2: float = Field(8.0, gt=0)
    emergency_jerk_mps3: float = Field(10.0, gt=0)
    emergency_ttc_s: float = Field(0.6, ge=0, description="full braking when the route TTC falls to this, s")
    cruise_accel_mps2: float = Field(2.0, gt=0)
    cruise_gain_per_s: float = Field(0.8, gt=0)
    corridor_margin_m: float = Field(0.25, ge=0)
    track_memory_s: float = Field(1.0, ge=0)

    @field_validator("emergency_decel_mps2")
    @classmethod
    def _emergency_at_least_comfort(cls, value: float, info: ValidationInfo) -> float:
        comfort = info.data.get("comfort_decel_mps2")
        if comfort is not None and value < comfort:
            raise ValueError(f"must be at least comfort_decel_mps2 ({comfort})")
        return value


NUMERIC = tuple(name for name in PredictiveParams.model_fields if name != "prediction")
(
    _ENVELOPE,
    _HORIZON,
    _STEP,
    _MARGIN_T,
    _FOLLOW_GAP,
    _STOP_GAP,
    _COMFORT_DECEL,
    _COMFORT_JERK,
    _EMERGENCY,
    _EMERGENCY_JERK,
    _EMERGENCY_TTC,
    _CRUISE_ACCEL,
    _CRUISE_GAIN,
    _MARGIN_M,
    _MEMORY,
) = range(len(NUMERIC))


class PredictivePlanner(PlannerBase):
    """Cruise / yield / follow / stop / emergency brake from predicted corridor occupancy, per variant."""

    mode_names = ("cruise", "yield", "follow", "stop", "emergency_brake")
    shared: ClassVar[frozenset[str]] = frozenset({"vru_paths"})
    """The VRU path table (variants address it by `vru_path_offset`)."""

    def reset(self, params: BatchParams) -> None:
        """Read per-variant parameters and the VRUs' declared paths; start every variant in cruise."""
        per_variant = validate_params(PredictiveParams, params)
        self.table = param_table(per_variant, NUMERIC)
        self.kind = np.array([PATH if p.prediction == "path" else CONSTANT_VELOCITY for p in per_variant])
        self.vru_paths = params.vru_paths.arrays
        self.vru_path_offset = params.vru_path_offset
        self.ego_length, self.rear_to_centre = 2.0 * params.half_length_m, params.rear_to_centre_m
        size, slots = params.size, params.vru_slots
        self.mode = np.zeros(size, dtype=np.int8)
        self.command = np.zeros(size)
        """The last command (where the next jerk ramp starts), m/s^2."""
        self.required_decel_mps2 = np.zeros(size)
        """The plan: gentlest deceleration that lets every yielded-to VRU clear first, before limits, m/s^2."""
        self.plan = np.full(size, np.inf)
        """The last plan: largest admissible constant acceleration, m/s^2 (inf: nothing to yield to)."""
        self.yielding = np.zeros((size, slots), dtype=bool)
        self.path_station = np.zeros((size, slots))
        self.tracks: np.ndarray | None = None
        self.station: np.ndarray | None = None

    def compact(self, index: np.ndarray) -> None:
        """Keep only variants `index` (the engine drops stopped ones); VRU paths are shared."""
        take_members(self, index)

    def act(self, obs: Observation) -> np.ndarray:
        """Plan each variant from the predicted occupancy of its corridor; return the acceleration command."""
        if self.tracks is None:
            self.tracks, self.station = new_tracks(obs)
        _predictive_step(
            self.mode.shape[0],
            obs.routes.arrays,
            obs.route_offset,
            obs.t_s,
            obs.dt_s,
            obs.ego_x_m + obs.rear_to_front_m * obs.ego_heading_x,
            obs.ego_y_m + obs.rear_to_front_m * obs.ego_heading_y,
            obs.ego_station_m + obs.rear_to_front_m,
            obs.rear_to_front_m,
            self.rear_to_centre,
            obs.ego_speed_mps,
            obs.cruise_speed_mps,
            obs.half_width_m,
            self.ego_length,
            obs.detected,
            obs.vru_estimate,
            obs.vru_radius_m,
            self.vru_paths,
            self.vru_path_offset,
            self.kind,
            self.table,
            self.tracks,
            self.station,
            self.path_station,
            self.yielding,
            self.mode,
            self.required_decel_mps2,
            self.plan,
            self.command,
            np.empty((self.mode.shape[0], 5)),
        )
        return self.command.copy()


@batch_kernel
def _predictive_step(
    route,
    offsets,
    t,
    dt,
    front_x,
    front_y,
    front_station,
    rear_to_front,
    rear_to_centre,
    speed,
    cruise_speed,
    half_width,
    ego_length,
    detected,
    estimate,
    radius,
    vru_paths,
    vru_offsets,
    kind,
    p,
    tracks,
    station,
    path_station,
    yielding,
    mode,
    required,
    last_plan,
    command,
    scratch,
):  # pragma: no cover (compiled)
    for b in prange(detected.shape[0]):
        predictive_variant(
            b,
            route,
            offsets,
            t,
            dt,
            front_x,
            front_y,
            front_station,
            rear_to_front,
            rear_to_centre,
            speed,
            cruise_speed,
            half_width,
            ego_length,
            detected,
            estimate,
            radius,
            vru_paths,
            vru_offsets,
            kind,
            p,
            tracks,
            station,
            path_station,
            yielding,
            mode,
            required,
            last_plan,
            command,
            scratch,
        )


@njit(cache=True, inline="always")
def predictive_variant(
    b,
    route,
    offsets,
    t,
    dt,
    front_x,
    front_y,
    front_station,
    rear_to_front,
    rear_to_centre,
    speed,
    cruise_speed,
    half_width,
    ego_length,
    detected,
    estimate,
    radius,
    vru_paths,
    vru_offsets,
    kind,
    p,
    tracks,
    station,
    path_station,
    yielding,
    mode,
    required,
    last_plan,
    command,
    scratch,
):  # pragma: no cover (compiled)
    """`_predictive_step` for variant b."""
    K = detected.shape[1]
    v = speed[b]
    horizon = p[b, _HORIZON]
    # how far along its route the ego can get within the planning window (for the reachability screen)
    reach_ego = max(v, cruise_speed[b]) * (horizon + p[b, _FOLLOW_GAP] + p[b, _MARGIN_T]) + ego_length[b]
    plan, plan_now, ttc, binding_lead, threat = np.inf, np.inf, np.inf, False, False
    bounds = scratch[b]  # [5], filled by occupancy_bounds
    # the new plan starts once the command has ramped down to the last plan (jerk-aware planning)
    comfort = p[b, _COMFORT_DECEL]
    ramp = p[b, _COMFORT_JERK] if last_plan[b] >= -comfort else p[b, _EMERGENCY_JERK]
    delay, ahead, plan_speed = plan_start(v, command[b], max(last_plan[b], -p[b, _EMERGENCY]), ramp)
    for k in range(K):
        was_known = t - tracks[b, k, 0] <= p[b, _MEMORY]
        known, x, y, vx, vy, ax, ay = update_track(t, detected[b, k], estimate, b, k, p[b, _MEMORY], tracks[b, k])
        if not known:
            yielding[b, k] = False
            continue
        r = radius[b, k]
        guess = warm_station(route, offsets[b], was_known, x, y, station[b, k])
        s_now, _, lead, _, _, _, _ = analyse_vru(
            route, offsets[b], guess, front_station[b], front_station[b], half_width[b], r, p[b, _MARGIN_M],
            ENTRY_HORIZON_S,
            x, y, vx, vy, 0.0, 0.0, False,
        )  # fmt: skip
        station[b, k] = s_now
        ttc = min(
            ttc,
            route_ttc(
                route, offsets[b], front_station[b] - rear_to_front[b], v, rear_to_centre[b],
                0.5 * ego_length[b], half_width[b], x, y, vx, vy, 0.0, r, p[b, _EMERGENCY_TTC],
            ),
        )  # fmt: skip
        v_vru = np.sqrt(vx * vx + vy * vy)
        if v_vru > 1e-6:
            ux, uy = vx / v_vru, vy / v_vru
        else:  # at rest: it would set off along its acceleration
            a_abs = np.sqrt(ax * ax + ay * ay)
            ux, uy = (ax / a_abs, ay / a_abs) if a_abs > 1e-6 else (0.0, 0.0)
        sigma = 0.0
        if kind[b] == PATH:
            sigma, ux, uy = path_station_of(vru_paths, vru_offsets[b, k], was_known, path_station[b, k], x, y)
            path_station[b, k] = sigma
        accel = ax * ux + ay * uy
        reach_vru = v_vru * horizon + 0.5 * max(accel, 0.0) * horizon * horizon
        dx, dy = x - front_x[b], y - front_y[b]
        if np.sqrt(dx * dx + dy * dy) > reach_ego + reach_vru + half_width[b] + r + p[b, _MARGIN_M]:
            yielding[b, k] = False  # cannot reach the part of the route the ego drives within the window
            continue
        bounds[0], bounds[1], bounds[2], bounds[3], bounds[4] = 0.0, 1.0, np.inf, -np.inf, np.inf
        margin = p[b, _FOLLOW_GAP] if lead else p[b, _MARGIN_T]
        profiles = 2 if (p[b, _ENVELOPE] > 0.5 and abs(accel) > 1e-3) else 1
        for profile in range(profiles):
            occupancy_bounds(
                route, offsets[b], s_now, kind[b], vru_paths, vru_offsets[b, k], sigma, x, y, ux, uy,
                v_vru, accel if profile == 1 else 0.0, horizon, p[b, _STEP], half_width[b], p[b, _MARGIN_M], r,
                front_station[b], v, ego_length[b], p[b, _MARGIN_T],
                (margin, p[b, _STOP_GAP], delay, ahead, plan_speed, cruise_speed[b]), bounds,
            )  # fmt: skip
        if bounds[0] < 0.5:
            yielding[b, k] = False  # it does not occupy the corridor ahead within the horizon
            continue
        if bounds[1] > 0.5 and not yielding[b, k]:
            continue  # the ego passes first
        yielding[b, k] = True
        threat = True
        if bounds[2] < plan:
            plan, binding_lead = bounds[2], lead
        plan_now = min(plan_now, bounds[4])

    last_plan[b] = plan if threat else np.inf
    cruise = p[b, _CRUISE_GAIN] * (cruise_speed[b] - v)
    cruise = min(max(cruise, -comfort), p[b, _CRUISE_ACCEL])
    required[b] = max(-plan, 0.0) if threat else 0.0
    if ttc <= p[b, _EMERGENCY_TTC]:
        mode[b] = EMERGENCY_BRAKE
        command[b] = -p[b, _EMERGENCY]
        return
    stopped = v <= STANDSTILL_MPS
    previous, jerk = command[b], p[b, _COMFORT_JERK]
    # braking beyond the comfort limit: when even a plan applied at once would need it (the ramp-aware plan
    # may exceed the limit by the ramp's delay alone); not in the last metre per second of a stop
    beyond = threat and v >= EMERGENCY_MIN_SPEED_MPS and plan_now < -comfort
    held = mode[b] == EMERGENCY_BRAKE and threat and not stopped and plan < -EMERGENCY_EXIT * comfort
    if beyond or held:
        mode[b] = EMERGENCY_BRAKE
        if plan <= -p[b, _EMERGENCY]:  # no time for a ramp: full braking at once
            command[b] = -p[b, _EMERGENCY]
            return
        target, jerk = plan, p[b, _EMERGENCY_JERK]
    else:
        # after braking beyond the comfort limit the ramp starts at that limit (the extra brake is released)
        previous = max(previous, -comfort)
        if not threat or plan >= cruise:
            mode[b] = CRUISE
            target = cruise
        else:
            target = max(plan, -comfort)
            mode[b] = FOLLOW if binding_lead else YIELD
            if stopped and plan < MOVE_OFF_MPS2:  # wait until the VRU has cleared or is far enough ahead
                target = min(target, 0.0)
                mode[b] = STOP
        if stopped and target > 0.0:
            previous = max(previous, 0.0)  # moving off: the brake held at standstill is released at once
    step = jerk * dt
    command[b] = previous + min(max(target - previous, -step), step)
