"""Each variant's sensor-model settings packed into arrays (`SensorParams`), from its scenario's `sensor` fields.

Durations become whole steps of `sim.dt_s` here, once, so that a sensor model reads only arrays after packing.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from vrusim.scenario.schema import Scenario

MAX_WHOLE_STEPS = 2**62
"""The most steps `whole_steps` gives (int64 with room to add): any count beyond a run's steps (at most
`schema.MAX_STEPS`) acts as never, so a longer duration (a latency of 10 s at dt = 1e-15 s) means the same."""


def whole_steps(duration_s: float | np.ndarray, dt_s: float) -> np.ndarray:
    """Durations in whole steps, rounded to the nearest (halves up, robust to round-off in duration / dt), at most
    `MAX_WHOLE_STEPS`; floats or arrays (int64)."""
    with np.errstate(over="ignore"):
        steps = np.floor(np.asarray(duration_s, dtype=float) / dt_s + 0.5 + 1e-9)
    return np.minimum(steps, float(MAX_WHOLE_STEPS)).astype(np.int64)


def history_depth(sensor: SensorParams, n_steps: int) -> int:
    """Steps the realistic sensor's ring buffer keeps: the largest latency L + 1, but at most the run's steps + 1.

    A latency of n_steps or more reports nothing during the run, exactly as one of n_steps does (the frame it
    would report lies before step 0 at every step), so the buffer never needs more rows than the run has steps.
    """
    return int(min(int(sensor.latency_steps.max()), max(n_steps, 1))) + 1


@dataclass(frozen=True)
class SensorParams:
    """Sensor-model settings per variant [B]."""

    ideal: np.ndarray
    """Whether the variant's sensor is ideal, bool: it detects every visible VRU at once and exactly (latency 0 steps,
    frame period 1 step, detection probability 1, no noise; lighting aside)."""
    latency_steps: np.ndarray
    """Detection latency L, whole steps (int64)."""
    frame_steps: np.ndarray
    """Frame period F, whole steps, at least 1 (int64)."""
    detection_probability: np.ndarray
    """Probability that a visible VRU is detected in a frame."""
    position_sigma_m: np.ndarray
    """Standard deviation of the reported x and y, m."""
    velocity_sigma_mps: np.ndarray
    """Standard deviation of the reported vx and vy, m/s."""


def pack_sensor(scenarios: Sequence[Scenario]) -> SensorParams:
    """The sensor settings of `scenarios` (one time step), one row per scenario: latency L = `whole_steps`
    (latency_s), frame period F = max(1, `whole_steps`(1 / frame_rate_hz)) or 1 without a frame rate."""
    dt = scenarios[0].sim.dt_s
    raw = np.array(
        [
            (
                s.sensor.latency_s,
                math.nan if s.sensor.frame_rate_hz is None else s.sensor.frame_rate_hz,
                s.sensor.detection_probability,
                s.sensor.position_sigma_m,
                s.sensor.velocity_sigma_mps,
            )
            for s in scenarios
        ],
        dtype=float,
    ).reshape(len(scenarios), 5)
    latency_s, rate_hz, probability, position_sigma, velocity_sigma = raw.T
    latency = whole_steps(latency_s, dt)
    with np.errstate(invalid="ignore"):
        frame = np.where(np.isnan(rate_hz), 1, np.maximum(1, whole_steps(1.0 / rate_hz, dt)))
    exact = (probability == 1.0) & (position_sigma == 0.0) & (velocity_sigma == 0.0)
    return SensorParams(
        ideal=exact & (latency == 0) & (frame == 1),
        latency_steps=latency,
        frame_steps=frame,
        detection_probability=probability.copy(),
        position_sigma_m=position_sigma.copy(),
        velocity_sigma_mps=velocity_sigma.copy(),
    )
