"""The engine's step (vrusim.engine.stepper) for episodes: what each step did, per variant, for rewards and done flags.

Every variant stays in the working set (no compaction), so row b is variant b throughout; an episode driven
by a planner's own commands reproduces `simulate` bit for bit (tests/test_gym.py checks it).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vrusim.engine.simulate import BatchRun
from vrusim.engine.stepper import BatchStepper, StopReason
from vrusim.sim.observation import Observation
from vrusim.sim.params import BatchParams


@dataclass
class EpisodeStep:
    """What one step did, per variant [B] (ground truth, for rewards and done flags)."""

    was_active: np.ndarray
    """Variant was running at the start of the step."""
    reason: np.ndarray
    """Why the variant stopped in this step (`vrusim.engine.stepper.StopReason` code; 0: it did not)."""
    terminated: np.ndarray
    """Stopped in this step by a collision (`stop_on_collision`) or at its route end (`stop_at_route_end`)."""
    truncated: np.ndarray
    """Stopped in this step by its duration or the batch's last step."""
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
    min_clearance_m: np.ndarray
    """Smallest clearance ego outline – VRU circle over the VRUs at the step end, m (inf: no VRU)."""


class EpisodeStepper:
    """B episodes in lock-step on one `BatchStepper`; call `observe()` then `advance(command)` once per step."""

    def __init__(self, params: BatchParams) -> None:
        self.params = params
        self.reset()

    def reset(self) -> None:
        """Every variant back at its initial state, time 0 (fresh sensor, channel and metrics)."""
        self.stepper = BatchStepper(self.params)

    @property
    def t_s(self) -> float:
        """Time of the current state, s."""
        return self.stepper.t_s

    def observe(self) -> Observation:
        """Sensing, V2X and fusion at the current time: the planner observation."""
        return self.stepper.observe()

    def advance(self, command: np.ndarray) -> EpisodeStep:
        """VRU and ego motion under `command` (m/s^2 per variant), contact and metrics; the engine's stop rules
        applied (`BatchStepper.advance`)."""
        stepper, params = self.stepper, self.params
        metrics, ego = stepper.metrics, stepper.ego
        was_active, collided_before = stepper.active.copy(), metrics.collided.copy()
        station_before, actuator_before = ego.station_m.copy(), ego.actuator_mps2.copy()
        moving_before = ego.speed_mps > 0.0
        reason = stepper.advance(command).reason
        ttc, clearance = stepper.ttc_s, stepper.clearance_m
        return EpisodeStep(
            was_active=was_active,
            reason=reason,
            terminated=(reason == StopReason.COLLISION) | (reason == StopReason.ROUTE_END),
            truncated=reason == StopReason.TIME_UP,
            collided=metrics.collided & ~collided_before,
            progress_m=ego.station_m - station_before,
            accel_mps2=ego.accel_mps2.copy(),
            jerk_mps3=np.where(moving_before, (ego.actuator_mps2 - actuator_before) / params.dt_s, 0.0),
            min_ttc_s=ttc.min(axis=1) if ttc.shape[1] else np.full(params.size, np.inf),
            min_clearance_m=clearance.min(axis=1) if clearance.shape[1] else np.full(params.size, np.inf),
        )

    def run(self) -> BatchRun:
        """The batch so far as a `BatchRun` (for `score_arrays` / `result_columns`; no planner modes)."""
        return BatchRun(self.params, self.stepper.finish(), ("running",), None, self.stepper.step_index)
