"""ACPE, accelerator control for pedal error (UN R175; Euro NCAP LSC26 CPMFC, §3.2.2.3 and §5.2.2), vectorised.

The ego follows its driver (`ego.driver`). When the driver presses the accelerator while a tracked VRU is in the
path within `suppress_distance_m` of the leading edge, ACPE cuts the accelerator: the command becomes the idle
request (`Observation.driver_idle_accel_mps2`, creeping), which is LSC26's pass criterion ("reduction of the
effective demand of the accelerator control to zero upon accelerator pedal input", §5.2.2: green). The cut holds
while the pedal stays pressed. With `brake_decel_mps2` > 0 it also brakes, from the suppressed state, once the
gap is within the stopping distance v^2 / (2 decel) + `stop_margin_m`, and holds the ego until the VRU has left
the path (beyond `suppress_distance_m`): our choice, not required by LSC26.

The gap is the distance along the route at which the ego's rectangle would first touch the VRU's circle: the
route TTC (`planners.route_ttc`) at a probe speed of 1 m/s, the VRU moving at its estimated velocity meanwhile
(exact for a stationary VRU, as in CPMFC). Modes: follow, suppress, brake. A variant without a driver holds its
speed (zero command) unless it brakes.
"""

from __future__ import annotations

import numpy as np
from pydantic import Field

from vrusim.kernels import batch_kernel, prange
from vrusim.planners.base import PlannerBase
from vrusim.planners.conflict import new_tracks, update_track
from vrusim.planners.params import param_table, validate_params
from vrusim.planners.route_ttc import route_ttc
from vrusim.scenario.strict import StrictModel
from vrusim.sim.compaction import take_members
from vrusim.sim.observation import Observation
from vrusim.sim.params import BatchParams

FOLLOW, SUPPRESS, BRAKE = 0, 1, 2
PROBE_SPEED_MPS = 1.0
"""The route TTC at this speed, s, is the gap along the route, m (for a stationary VRU)."""


class AcpeParams(StrictModel):
    """Parameters of the ACPE planner (YAML `planner.params`)."""

    suppress_distance_m: float = Field(4.0, gt=0, description="cut the accelerator for a VRU in path this near, m")
    brake_decel_mps2: float = Field(6.0, ge=0, description="braking once suppressed; 0: suppression only")
    stop_margin_m: float = Field(0.5, ge=0, description="brake when gap <= v^2 / (2 decel) + this, m")
    track_memory_s: float = Field(1.0, ge=0, description="how long a lost VRU is still considered, s")


PARAM_ORDER = tuple(AcpeParams.model_fields)
_DISTANCE, _DECEL, _MARGIN, _MEMORY = range(len(PARAM_ORDER))


class AcpePlanner(PlannerBase):
    """Follow the driver; cut the accelerator (and brake) for a VRU in the path ahead."""

    mode_names = ("follow", "suppress", "brake")

    def reset(self, params: BatchParams) -> None:
        """Read per-variant parameters; every variant starts following its driver."""
        self.table = param_table(validate_params(AcpeParams, params), PARAM_ORDER)
        self.half_length, self.rear_to_centre = params.half_length_m, params.rear_to_centre_m
        self.mode = np.zeros(params.size, dtype=np.int8)
        self.gap_m = np.full(params.size, np.inf)
        """Route gap to the nearest VRU in the path at the last step, m (inf: none within reach)."""
        self.tracks: np.ndarray | None = None

    def compact(self, index: np.ndarray) -> None:
        """Keep only variants `index` (the engine drops stopped ones)."""
        take_members(self, index)

    def act(self, obs: Observation) -> np.ndarray:
        """Mode and command of each variant."""
        if self.tracks is None:
            self.tracks, _ = new_tracks(obs)
        size = self.mode.shape[0]
        has_driver, request = obs.driver_request()
        idle = obs.driver_idle_accel_mps2 if obs.driver_idle_accel_mps2 is not None else np.zeros(size)
        pressed = obs.driver_accelerator if obs.driver_accelerator is not None else np.zeros(size, dtype=bool)
        command = np.empty(size)
        _acpe_step(
            size, obs.routes.arrays, obs.route_offset, obs.t_s, obs.ego_station_m, self.rear_to_centre,
            obs.ego_speed_mps, self.half_length, obs.half_width_m, obs.detected, obs.vru_estimate, obs.vru_radius_m,
            self.table, self.tracks, has_driver, request, idle, pressed, self.mode, self.gap_m, command,
        )  # fmt: skip
        return command


@batch_kernel
def _acpe_step(
    path,
    offsets,
    t,
    rear_station,
    rear_to_centre,
    speed,
    half_length,
    half_width,
    detected,
    estimate,
    radius,
    p,
    tracks,
    has_driver,
    request,
    idle,
    pressed,
    mode,
    gap_out,
    command,
):  # pragma: no cover (compiled)
    B, K = detected.shape
    for b in prange(B):
        reach = p[b, _DISTANCE]
        gap = np.inf
        for k in range(K):
            known, x, y, vx, vy, _, _ = update_track(t, detected[b, k], estimate, b, k, p[b, _MEMORY], tracks[b, k])
            if known:
                gap = min(
                    gap,
                    PROBE_SPEED_MPS * route_ttc(
                        path, offsets[b], rear_station[b], PROBE_SPEED_MPS, rear_to_centre[b], half_length[b],
                        half_width[b], x, y, vx, vy, 0.0, radius[b, k], reach / PROBE_SPEED_MPS,
                    ),
                )  # fmt: skip
        gap_out[b] = gap
        threat = gap <= reach
        v = speed[b]
        if not threat:
            mode[b] = FOLLOW
        elif mode[b] == FOLLOW and pressed[b]:
            mode[b] = SUPPRESS
        elif mode[b] == SUPPRESS and not pressed[b]:
            mode[b] = FOLLOW
        decel = p[b, _DECEL]
        if mode[b] == SUPPRESS and decel > 0.0 and gap <= v * v / (2.0 * decel) + p[b, _MARGIN]:
            mode[b] = BRAKE
        if mode[b] == BRAKE:
            command[b] = -decel
        elif mode[b] == SUPPRESS:
            command[b] = idle[b]
        else:
            command[b] = request[b] if has_driver[b] else 0.0
