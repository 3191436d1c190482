"""One step of the batch engine, driven from outside: `observe()`, then `advance(command)`.

`simulate` (vrusim.engine.simulate) runs it with a planner's commands; Gymnasium environments (vrusim.gym) with an
agent's. From the state at time t: `observe()` does sensing (sector, occlusion → sensor model), V2X (RSU →
channel) and fusion and returns the planner observation; `advance(command)` moves the VRUs (triggers judged on
the ego state at t) and the egos to t + dt, checks contact, folds the step into the streamed metrics and
applies the stop rules, and returns a `StepOutcome`: which variants stopped in this step and why (`StopReason`).
`compact()` drops stopped variants from the working set; `finish()` writes the working
set's metrics back into the whole batch's.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import IntEnum
from typing import NamedTuple

import numpy as np

from vrusim.engine.accumulators import RunMetrics
from vrusim.errors import UserInputError
from vrusim.geometry.contact import clearance_batch
from vrusim.geometry.ttc import ttc_batch
from vrusim.kernels import njit
from vrusim.sim.compaction import take
from vrusim.sim.door import initial_door, update_doors
from vrusim.sim.driver import initial_driver, update_driver
from vrusim.sim.ego import advance_egos
from vrusim.sim.observation import Observation, fuse
from vrusim.sim.params import BatchParams
from vrusim.sim.sensing.sector import sense
from vrusim.sim.sensing.sensor_model import SensorModel, make_sensor_model
from vrusim.sim.state import EgoState, initial_ego, initial_vrus
from vrusim.sim.v2x.channel import make_channel
from vrusim.sim.v2x.messages import Channel, V2xMessages, rsu_broadcast
from vrusim.sim.vru import motion as _point_mass_step  # noqa: F401  (attaches the built-in model's step)
from vrusim.sim.vru import shaped_motion as _shaped_step  # noqa: F401  (attaches the cubic and sinusoidal steps)
from vrusim.sim.vru.registry import vru_motion


class StopReason(IntEnum):
    """Why a variant stopped (`StepOutcome.reason`); when several hold in one step, the first listed wins."""

    RUNNING = 0
    """Not stopped in this step."""
    COLLISION = 1
    """It collided and `sim.stop_on_collision` is set."""
    ROUTE_END = 2
    """It completed its route and `sim.stop_at_route_end` is set."""
    TIME_UP = 3
    """It reached its duration (`sim.duration_s`), or the batch its last step."""


_COLLISION, _ROUTE_END, _TIME_UP = int(StopReason.COLLISION), int(StopReason.ROUTE_END), int(StopReason.TIME_UP)


class StepOutcome(NamedTuple):
    """What the stop rules decided in one step, per working-set variant. A step in which no variant stopped
    returns a shared outcome whose `reason` is read-only zeros (no allocation in the common case)."""

    reason: np.ndarray
    """`StopReason` code per variant [B] (int8): why it stopped in this step, 0 (`RUNNING`) if it did not
    (still running, or stopped before this step). Read-only; a step's own array, kept valid after later steps."""
    running: int
    """How many variants of the working set still run."""

    @property
    def stopped(self) -> np.ndarray:
        """Variants that stopped in this step [B] (bool)."""
        return self.reason != StopReason.RUNNING


@dataclass
class _Scratch:
    """Per working set: read-only views of the state the planner observes, and reused step buffers."""

    ego_view: list[np.ndarray]
    route_offset: np.ndarray
    radius: np.ndarray
    fresh: np.ndarray
    """Age of an ideal sensor's reports, s (0)."""
    contact: np.ndarray
    """Clearance, outline x, outline y [3, B, K], m."""
    ttc: np.ndarray
    """Time to collision per VRU [B, K], s."""
    reason: np.ndarray
    """The stop-rule kernel's output [B] (int8), copied into a `StepOutcome` when a variant stopped."""
    no_stop: np.ndarray
    """The `StepOutcome.reason` of a step in which no variant stopped: zeros [B], read-only, shared."""
    low_speed: list[np.ndarray]
    """Read-only views of the driver's request and the door state, and `has_driver` (the observation's)."""
    no_hold: np.ndarray
    """Door retention when the planner holds no door: False [B]."""


def _scratch(params: BatchParams, ego: EgoState, driver, door) -> _Scratch:
    # kernels update the state arrays in place, views follow
    ego_view = [
        _read_only(a)
        for a in (ego.x_m, ego.y_m, ego.heading_x, ego.heading_y, ego.speed_mps, ego.accel_mps2, ego.station_m)
    ] + [_read_only(a) for a in (params.cruise_speed_mps, params.rear_to_front_m, params.half_width_m)]
    ego_view.append(_read_only(2.0 * params.half_length_m))  # Observation.ego_length_m
    shape = params.vru_valid.shape
    return _Scratch(
        ego_view,
        _read_only(params.route_offset),
        _read_only(params.vru_radius_m),
        np.zeros(params.size),
        np.full((3, *shape), np.inf),  # before the first step: no contact known
        np.full(shape, np.inf),
        np.zeros(params.size, dtype=np.int8),
        _read_only(np.zeros(params.size, dtype=np.int8)),
        [
            _read_only(a)
            for a in (
                driver.accel_mps2,
                driver.idle_accel_mps2,
                driver.accelerator,
                params.driver.has,
                door.requested,
                door.angle_rad,
            )
        ],
        np.zeros(params.size, dtype=bool),
    )


class BatchStepper:
    """B variants in lock-step. Per step: `observe()`, then `advance(command)` (m/s² per working-set variant).

    `params`, `ego`, `vrus`, `active` and `work` (the metrics) describe the working set: all variants, or after
    `compact()` those still running. `metrics` is the whole batch's; call `finish()` before reading it.
    """

    def __init__(
        self, params: BatchParams, n_modes: int = 1, channel: Channel | None = None, sensor: SensorModel | None = None
    ) -> None:
        self.batch = params
        self.params = params
        self.channel = channel if channel is not None else make_channel(params)
        self.sensor = sensor if sensor is not None else make_sensor_model(params)
        self.channel.reset(params)
        self.sensor.reset(params)
        self.metrics = RunMetrics(params, n_modes)
        self.work = self.metrics
        self.ego = initial_ego(params)
        self.vrus = initial_vrus(params)
        self.active = np.ones(params.size, dtype=bool)
        self.driver = initial_driver(params.size)
        self.door = initial_door(params.size, params.vru_slots)
        self._advance_vrus = _vru_step(params)
        self._n_steps = params.n_steps
        self.step_index = 0
        self.detected = self.source = None
        self.messages: V2xMessages | None = None
        """What V2X delivered at the last `observe` (traces record the messages' ages)."""
        self._front: tuple[np.ndarray, np.ndarray] | None = None
        self._scratch = _scratch(params, self.ego, self.driver, self.door)
        self._low_speed()
        self._quiet = StepOutcome(self._scratch.no_stop, params.size)
        """The outcome of a step in which no variant stopped (reused while the running count stays the same)."""

    def _low_speed(self) -> None:
        """Set `has_driver` / `has_door`: whether the working set has drivers / doors (their per-step work runs
        only then)."""
        self.has_driver = bool(self.params.driver.has.any())
        self.has_door = bool(self.params.door.has.any())

    @property
    def t_s(self) -> float:
        """Time of the current state, s."""
        return self.step_index * self.params.dt_s

    @property
    def clearance_m(self) -> np.ndarray:
        """Clearance ego outline – VRU circle per VRU [B, K] after the last step, m (negative: overlap)."""
        return self._scratch.contact[0]

    @property
    def ttc_s(self) -> np.ndarray:
        """Time to collision per VRU [B, K] after the last step, s (inf: none)."""
        return self._scratch.ttc

    def observe(self) -> Observation:
        """Sensing, V2X and fusion at the current time; first detections are recorded in the metrics."""
        params, ego, vrus, scratch = self.params, self.ego, self.vrus, self._scratch
        step, dt = self.step_index, params.dt_s
        t = step * dt
        front_x, front_y = ego.front_x_m.copy(), ego.front_y_m.copy()
        visible = sense(params, front_x, front_y, ego, vrus)
        sensed, sensed_kinematics = self.sensor.observe(step, t, visible, vrus.kinematics)
        messages = self.channel.deliver(t, rsu_broadcast(params, ego.centre_x_m, ego.centre_y_m, vrus.kinematics))
        sensor_age = self.sensor.age_s(step, dt)
        detected, source, estimate = fuse(
            sensed, sensed_kinematics, messages, scratch.fresh if sensor_age is None else sensor_age
        )
        self.work.record_detection(t, self.active, sensed, messages.received)
        self._front = (front_x, front_y)
        self.detected, self.source, self.messages = detected, source, messages
        if self.has_driver:
            update_driver(params.driver, self.driver, t, dt, ego.speed_mps, ego.station_m, params.max_decel_mps2)
        return Observation(
            t, dt, *scratch.ego_view, params.routes, scratch.route_offset, detected, source, estimate,
            scratch.radius, *scratch.low_speed,
        )  # fmt: skip

    def advance(self, command: np.ndarray, door_hold: np.ndarray | None = None) -> StepOutcome:
        """Move VRUs and egos to t + dt under `command`, check contact, record metrics, apply the stop rules;
        return which variants stopped and why, and how many of the working set still run. After the batch's
        last step (`n_steps`) every variant has stopped. `door_hold` [B] (bool): door retention, the planner
        holding each variant's door closed during this step (None: no door held)."""
        if self._front is None:
            raise RuntimeError("BatchStepper.advance: call observe() first in every step")
        params, ego, vrus, scratch = self.params, self.ego, self.vrus, self._scratch
        t = self.step_index * params.dt_s
        front_x, front_y = self._front
        self._front = None
        moving_before = ego.speed_mps > 0.0
        self._advance_vrus(params, vrus, t, front_x, front_y, ego.speed_mps, ego.station_m)
        advance_egos(params, ego, command)
        self.step_index += 1
        t_next = self.step_index * params.dt_s
        centre_x, centre_y = ego.centre_x_m, ego.centre_y_m
        clearance_batch(
            params.size, centre_x, centre_y, ego.heading_x, ego.heading_y, params.half_length_m,
            params.half_width_m, vrus.x_m, vrus.y_m, params.vru_radius_m, scratch.contact,
        )  # fmt: skip
        ttc_batch(
            params.size, centre_x, centre_y, ego.heading_x, ego.heading_y, params.half_length_m,
            params.half_width_m, ego.speed_mps, vrus.x_m, vrus.y_m, params.vru_radius_m, vrus.vx_mps, vrus.vy_mps,
            scratch.ttc,
        )  # fmt: skip
        if self.has_door:
            hold = scratch.no_hold if door_hold is None else np.asarray(door_hold, dtype=bool)
            update_doors(
                params.door, self.door, hold, t, t_next, ego, vrus.x_m, vrus.y_m, params.vru_radius_m, scratch.contact
            )
        clearance, outline_x, outline_y = scratch.contact
        work = self.work
        work.record_step(
            t_next, self.active, ego, moving_before, clearance, outline_x, outline_y, scratch.ttc, vrus, self.door.hit
        )
        reason = scratch.reason
        running = _update_active(
            t_next,
            self.step_index >= self._n_steps,
            self.active,
            reason,
            params.stop_on_collision,
            work.collided,
            params.stop_at_route_end,
            work.travel_time_s,
            params.duration_s,
        )
        if running == self._quiet.running:  # nobody stopped: the same outcome as the last quiet step
            return self._quiet
        self._quiet = StepOutcome(scratch.no_stop, running)
        return StepOutcome(_read_only(reason.copy()), running)

    def compact(self) -> np.ndarray:
        """Drop the stopped variants from the working set (their results are final); return the kept rows of
        the previous working set, for the planner's own `compact`."""
        keep = np.flatnonzero(self.active)
        self.params = take(self.params, keep)
        self.ego, self.vrus = take(self.ego, keep), take(self.vrus, keep)
        self.driver, self.door = take(self.driver, keep), take(self.door, keep)
        self.channel.compact(keep)
        self.sensor.compact(keep)
        self.metrics.merge(self.work)
        self.work = self.work.subset(keep, self.params)
        self.active = np.ones(keep.size, dtype=bool)
        self._scratch = _scratch(self.params, self.ego, self.driver, self.door)
        self._low_speed()
        self._quiet = StepOutcome(self._scratch.no_stop, keep.size)
        return keep

    def finish(self) -> RunMetrics:
        """The whole batch's metrics, with the working set's written back."""
        if self.work is not self.metrics:
            self.metrics.merge(self.work)
        return self.metrics


def _vru_step(params: BatchParams):
    """The step of the batch's VRU motion model; a model registered without one is a UserInputError."""
    advance = vru_motion(params.vru_motion).advance
    if advance is None:
        raise UserInputError(f"vrus[].motion: VRU motion model {params.vru_motion!r} has no step (`advance`)")
    return advance


@njit(cache=True, _nrt=False)
def _update_active(
    t_next, last_step, active, reason, stop_on_collision, collided, stop_at_route_end, travel_time, duration
):  # pragma: no cover (compiled)
    """Stop the variants that collided (if `stop_on_collision`), completed their route (if
    `stop_at_route_end`) or reached their duration (all of them after the `last_step`); write why into
    `reason` (0 where none stopped now) and return how many still run (serial: a reduction)."""
    running = 0
    for b in range(active.shape[0]):
        reason[b] = 0
        if active[b]:
            if stop_on_collision[b] and collided[b]:
                reason[b] = _COLLISION
            elif stop_at_route_end[b] and travel_time[b] >= 0.0:
                reason[b] = _ROUTE_END
            elif last_step or not t_next < duration[b] - 1e-9:
                reason[b] = _TIME_UP
            active[b] = reason[b] == 0
        running += 1 if active[b] else 0
    return running


def _read_only(array: np.ndarray) -> np.ndarray:
    """A read-only view, so that a planner cannot change the simulation state it observes."""
    view = array.view()
    view.flags.writeable = False
    return view


def checked_planner_command(command, size: int, name: str) -> np.ndarray:
    """The planner's acceleration command as a finite float array of shape [B], or one clear error."""
    try:
        array = np.asarray(command, dtype=float)
    except (TypeError, ValueError):
        array = np.full(0, np.nan)
    if array.shape != (size,) or not np.isfinite(array).all():
        raise UserInputError(
            f"planner.name: planner {name!r} must return a finite acceleration per variant, shape ({size},); "
            f"got shape {array.shape}" + ("" if array.shape != (size,) else " with NaN or infinite values")
        )
    return array
