"""Per-step reward from the safety, efficiency and comfort metrics (formula and rationale: docs/interop.md).

    r_t = w_progress · min(Δs_t, v_cruise · dt) / L
        − w_comfort  · ((a_t / A)² + (j_t / J)²) · dt / T_ref
        − w_safety   · max(0, 1 − TTC_t / TTC_thr, 1 − d_t / d_thr) · dt / T_ref
        − w_collision · [first contact in step t]
        + w_scores   · (S + E + C) / 3 · [episode ends in step t]

Δs_t: distance travelled along the route (m); L: route length (m); a_t: acceleration achieved (m/s²); j_t:
actuator jerk (m/s³); TTC_t: smallest true time-to-collision at the step end (s); d_t: smallest clearance at
the step end (m); A, J, TTC_thr, d_thr: the scenario's score profile (`metrics.profile`, with the scenario's
`metrics.safety_*` thresholds; no clearance term when the profile has no clearance threshold); T_ref =
L / v_cruise, the free-flow travel time (the duration when v_cruise = 0); S, E, C: the episode's safety,
efficiency and comfort scores (`metrics.scores`, 0 / 0 / 0 after a collision).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from vrusim.gym.stepper import EpisodeStep
from vrusim.metrics.scores import profile
from vrusim.sim.params import BatchParams


@dataclass(frozen=True)
class RewardWeights:
    """Weights of the reward terms (dimensionless)."""

    progress: float = 1.0
    comfort: float = 1.0
    safety: float = 1.0
    collision: float = 10.0
    scores: float = 1.0


class RewardModel:
    """Constants of the reward for one batch, and the per-step reward of its variants."""

    def __init__(self, params: BatchParams, weights: RewardWeights) -> None:
        self.weights = weights
        profiles = [
            replace(profile(name), **overrides)
            for name, overrides in zip(params.score_profiles, params.score_overrides, strict=True)
        ]
        self.accel_scale = np.array([p.accel_scale_mps2 for p in profiles])
        self.jerk_scale = np.array([p.jerk_scale_mps3 for p in profiles])
        self.ttc_threshold = np.array([p.ttc_threshold_s for p in profiles])
        self.clearance_threshold = np.array([p.clearance_threshold_m or np.nan for p in profiles])
        """m; NaN: the profile has no proximity term."""
        cruise = params.cruise_speed_mps
        self.length = np.maximum(params.route_length_m, 1e-9)
        self.step_progress = cruise * params.dt_s
        with np.errstate(divide="ignore"):
            free = np.where(cruise > 0, params.route_length_m / np.maximum(cruise, 1e-9), params.duration_s)
        self.step_weight = params.dt_s / np.maximum(free, params.dt_s)

    def step(self, outcome: EpisodeStep, scores: np.ndarray | None) -> np.ndarray:
        """Reward of every variant for the step [B] (0 for variants that had already stopped).

        `scores` [B]: mean of the episode's three scores where the episode ended in this step (else unused).
        """
        w, o = self.weights, outcome
        progress = np.minimum(np.maximum(o.progress_m, 0.0), self.step_progress) / self.length
        discomfort = (o.accel_mps2 / self.accel_scale) ** 2 + (o.jerk_mps3 / self.jerk_scale) ** 2
        danger = np.maximum(0.0, 1.0 - np.minimum(o.min_ttc_s, 1e9) / self.ttc_threshold)
        close = 1.0 - np.maximum(np.minimum(o.min_clearance_m, 1e9), 0.0) / self.clearance_threshold
        danger = np.maximum(danger, np.where(np.isnan(self.clearance_threshold), 0.0, close))
        reward = (
            w.progress * progress
            - (w.comfort * discomfort + w.safety * danger) * self.step_weight
            - w.collision * o.collided
        )
        ended = o.terminated | o.truncated
        if scores is not None:
            reward = reward + w.scores * np.where(ended, scores, 0.0)
        return np.where(o.was_active, reward, 0.0)
