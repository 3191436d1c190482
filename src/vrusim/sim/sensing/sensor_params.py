"""Each variant's sensor-model settings packed into arrays (`SensorParams`), from its scenario's `sensor` fields.

Durations become whole steps of `sim.dt_s` here, once, so that a sensor model reads only arrays after packing.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from vrusim.scenario.schema import Scenario


def whole_steps(duration_s: float, dt_s: float) -> int:
    """A duration in whole steps, rounded to the nearest (halves up, robust to round-off in duration / dt)."""
    return math.floor(duration_s / dt_s + 0.5 + 1e-9)


def latency_steps(scenario: Scenario) -> int:
    """The scenario's sensor latency L in whole steps of its `sim.dt_s`."""
    return whole_steps(scenario.sensor.latency_s, scenario.sim.dt_s)


def frame_steps(scenario: Scenario) -> int:
    """The scenario's sensor frame period F in whole steps (at least 1; 1 without `frame_rate_hz`)."""
    rate = scenario.sensor.frame_rate_hz
    return 1 if rate is None else max(1, whole_steps(1.0 / rate, scenario.sim.dt_s))


def is_ideal(scenario: Scenario) -> bool:
    """Whether the scenario's sensor reports every visible VRU at once and exactly (lighting aside)."""
    sensor = scenario.sensor
    exact = sensor.detection_probability == 1.0 and sensor.position_sigma_m == 0.0 and sensor.velocity_sigma_mps == 0.0
    if not exact:
        return False
    if sensor.latency_s == 0.0 and sensor.frame_rate_hz is None:  # the defaults: no rounding to do
        return True
    return latency_steps(scenario) == 0 and frame_steps(scenario) == 1


@dataclass(frozen=True)
class SensorParams:
    """Sensor-model settings per variant [B]."""

    ideal: np.ndarray
    """Whether the variant's sensor is ideal (`is_ideal`), bool."""
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
    """The sensor settings of `scenarios` (one time step), one row per scenario; the same rules as
    `latency_steps`, `frame_steps` and `is_ideal`, on arrays (the same floating-point operations)."""
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
    latency = np.floor(latency_s / dt + 0.5 + 1e-9).astype(np.int64)
    with np.errstate(invalid="ignore"):
        frame = np.where(np.isnan(rate_hz), 1, np.maximum(1, np.floor(1.0 / rate_hz / dt + 0.5 + 1e-9)))
    frame = frame.astype(np.int64)
    exact = (probability == 1.0) & (position_sigma == 0.0) & (velocity_sigma == 0.0)
    return SensorParams(
        ideal=exact & (latency == 0) & (frame == 1),
        latency_steps=latency,
        frame_steps=frame,
        detection_probability=probability.copy(),
        position_sigma_m=position_sigma.copy(),
        velocity_sigma_mps=velocity_sigma.copy(),
    )
