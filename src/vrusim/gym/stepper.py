"""The batch engine's step loop, driven from outside: observe, then advance under a given command.

`BatchStepper` calls the same simulation functions as `vrusim.sim.engine.simulate`, in the same order, so that
an episode driven by a planner's own commands reproduces `simulate` bit for bit (tests/test_gym.py checks it):
`observe()` is the first half of a step (sensing → V2X channel → fused observation, detections recorded) and
`advance(command)` the second (VRU motion → ego motion → contact, TTC and streaming metrics → stop rules).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vrusim.metrics.streaming import RunMetrics
from vrusim.metrics.ttc import ttc_batch
from vrusim.sim.batch import BatchParams
from vrusim.sim.contact import clearance_batch
from vrusim.sim.ego_dynamics import advance_egos
from vrusim.sim.engine import BatchRun
from vrusim.sim.observation import Observation, fuse
from vrusim.sim.sensing import sense
from vrusim.sim.sensor_model import make_sensor_model
from vrusim.sim.state import initial_ego, initial_vrus
from vrusim.sim.v2x import make_channel, rsu_broadcast
from vrusim.sim.vru_motion import advance_vrus


@dataclass
class StepOutcome:
    """What one step did, per variant [B] (ground truth, for rewards and done flags)."""

    was_active: np.ndarray
    """Variant was running at the start of the step."""
    terminated: np.ndarray
    """Stopped in this step by a collision (`stop_on_collision`) or at its route end (`stop_at_route_end`)."""
    truncated: np.ndarray
    """Stopped in this step by its duration (and not terminated)."""
    collided: np.ndarray
    """First contact happened in this step."""
    progress_m: np.ndarray
    """Distance travelled along the route in this step, m."""
    accel_mps2: np.ndarray
    """Acceleration achieved over the step, m/s^2."""
    jerk_mps3: np.ndarray
    """Actuator jerk over the step, m/s^3 (0 while the ego stood at the step start, as in the metrics)."""
    min_ttc_s: np.ndarray
    """Smallest true time-to-collision over the VRUs at the step end, s (inf: none)."""


class BatchStepper:
    """B variants advanced in lock-step; call `observe()` then `advance(command)` once per step."""

    def __init__(self, params: BatchParams) -> None:
        self.params = params
        self.reset()

    def reset(self) -> None:
        """Every variant back at its initial state, time 0 (fresh sensor, channel and metrics)."""
        params = self.params
        self.channel = make_channel(params)
        self.sensor = make_sensor_model(params)
        self.channel.reset(params)
        self.sensor.reset(params)
        self.metrics = RunMetrics(params, 1)
        self.ego = initial_ego(params)
        self.vrus = initial_vrus(params)
        self.active = np.ones(params.size, dtype=bool)
        self.step_index = 0
        self._front: tuple[np.ndarray, np.ndarray] | None = None
        self._fresh = np.zeros(params.size)
        ego = self.ego
        self._ego_view = [
            _read_only(a)
            for a in (ego.x_m, ego.y_m, ego.heading_x, ego.heading_y, ego.speed_mps, ego.accel_mps2, ego.station_m)
        ] + [_read_only(a) for a in (params.cruise_speed_mps, params.rear_to_front_m, params.half_width_m)]
        self._route_offset, self._radius = _read_only(params.route_offset), _read_only(params.vru_radius_m)

    @property
    def t_s(self) -> float:
        """Time of the current state, s."""
        return self.step_index * self.params.dt_s

    @property
    def done(self) -> bool:
        """No variant is running any more (or the batch's last step has been taken)."""
        return not self.active.any() or self.step_index >= self.params.n_steps

    def observe(self) -> Observation:
        """Sensing, V2X and fusion at the current time: the planner observation (detections are recorded)."""
        params, ego, vrus = self.params, self.ego, self.vrus
        step, dt = self.step_index, params.dt_s
        t = step * dt
        front_x, front_y = ego.front_x_m.copy(), ego.front_y_m.copy()
        visible = sense(params, front_x, front_y, ego, vrus)
        sensed, sensed_kinematics = self.sensor.observe(step, t, visible, vrus.kinematics)
        messages = self.channel.deliver(t, rsu_broadcast(params, ego.centre_x_m, ego.centre_y_m, vrus.kinematics))
        sensor_age = self.sensor.age_s(step, dt)
        detected, source, estimate = fuse(
            sensed, sensed_kinematics, messages, self._fresh if sensor_age is None else sensor_age
        )
        self.metrics.record_detection(t, self.active, sensed, messages.received)
        self._front = (front_x, front_y)
        return Observation(
            t, dt, *self._ego_view, params.routes, self._route_offset, detected, source, estimate, self._radius
        )

    def advance(self, command: np.ndarray) -> StepOutcome:
        """VRU and ego motion under `command` (m/s^2 per variant), contact and metrics; stop rules applied."""
        if self._front is None:
            raise RuntimeError("BatchStepper.advance: call observe() first in every step")
        params, ego, vrus, metrics = self.params, self.ego, self.vrus, self.metrics
        dt = params.dt_s
        t = self.step_index * dt
        front_x, front_y = self._front
        self._front = None
        was_active, collided_before = self.active, metrics.collided.copy()
        station_before, actuator_before = ego.station_m.copy(), ego.actuator_mps2.copy()
        moving_before = ego.speed_mps > 0.0
        advance_vrus(params, vrus, t, front_x, front_y, ego.speed_mps, ego.station_m)
        advance_egos(params, ego, command)
        t_next = (self.step_index + 1) * dt
        centre_x, centre_y = ego.centre_x_m, ego.centre_y_m
        clearance, outline_x, outline_y = clearance_batch(
            params.size, centre_x, centre_y, ego.heading_x, ego.heading_y, params.half_length_m,
            params.half_width_m, vrus.x_m, vrus.y_m, params.vru_radius_m,
        )  # fmt: skip
        ego_vx, ego_vy = ego.speed_mps * ego.heading_x, ego.speed_mps * ego.heading_y
        ttc = ttc_batch(
            params.size, centre_x, centre_y, ego.heading_x, ego.heading_y, params.half_length_m,
            params.half_width_m, ego_vx, ego_vy, vrus.x_m, vrus.y_m, params.vru_radius_m, vrus.vx_mps, vrus.vy_mps,
        )  # fmt: skip
        metrics.record_step(t_next, was_active, ego, moving_before, clearance, outline_x, outline_y, ttc, vrus)
        stopped = (params.stop_on_collision & metrics.collided) | (
            params.stop_at_route_end & (metrics.travel_time_s >= 0.0)
        )
        timed_out = ~(t_next < params.duration_s - 1e-9)
        self.step_index += 1
        if self.step_index >= params.n_steps:  # the engine's loop ends here whatever the stop rules say
            timed_out = np.ones(params.size, dtype=bool)
        self.active = was_active & ~stopped & ~timed_out
        terminated = was_active & stopped
        return StepOutcome(
            was_active=was_active,
            terminated=terminated,
            truncated=was_active & ~stopped & timed_out,
            collided=metrics.collided & ~collided_before,
            progress_m=ego.station_m - station_before,
            accel_mps2=ego.accel_mps2.copy(),
            jerk_mps3=np.where(moving_before, (ego.actuator_mps2 - actuator_before) / dt, 0.0),
            min_ttc_s=ttc.min(axis=1) if ttc.shape[1] else np.full(params.size, np.inf),
        )

    def run(self) -> BatchRun:
        """The batch so far as a `BatchRun` (for `score_arrays` / `result_columns`; no planner modes)."""
        return BatchRun(self.params, self.metrics, ("running",), None, self.step_index)


def _read_only(array: np.ndarray) -> np.ndarray:
    """A read-only view, so that a planner cannot change the simulation state it observes."""
    view = array.view()
    view.flags.writeable = False
    return view
