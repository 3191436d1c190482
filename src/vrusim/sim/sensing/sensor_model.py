"""What the onboard sensor reports, given which VRUs its sector sees: ideal, or with latency, misses and noise.

A sensor model turns the geometric visibility of this step (`sensing.sense`) and the true VRU kinematics into
the sensor's report: which VRUs it detects and their estimated kinematics. The ideal model (the paper's
assumption) reports every visible VRU at once and exactly. The realistic model adds, per variant (scenario
`sensor` fields): a detection latency of L whole steps, a frame period of F whole steps, an independent
detection draw per frame and VRU, and Gaussian noise on the reported position and velocity. Both are
registered, in this order, in `vrusim.sim.sensing.registry`; `make_sensor_model` makes the first that applies:
the ideal model when every variant of the batch has ideal settings, so such runs stay bit-identical, else the
realistic one.

Realistic report at step n (docs/models.md, "Sensor model"): frames are measured at steps m = 0, F, 2F, ...
and reported L steps later, at n = m + L; between reports the last one is held. A frame detects VRU k when
it was visible at step m and u(seed, m, STREAM_SENSOR_DETECT, k) < detection_probability; its estimate is the
true x, y, vx, vy at step m plus sigma·z(seed, m, STREAM_SENSOR_NOISE, 4k + axis), and the true ax, ay at
step m without noise. Every draw is keyed by the variant's seed and the measurement step, never by the batch.
"""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from vrusim.kernels import batch_kernel, njit, prange
from vrusim.sim.compaction import take_members
from vrusim.sim.params import BatchParams
from vrusim.sim.rng import STREAM_SENSOR_DETECT, STREAM_SENSOR_NOISE, normal, uniform
from vrusim.sim.sensing.registry import SensorModel, register_sensor_model, sensor_model_entry
from vrusim.sim.sensing.sensor_params import history_depth

NOISY_ROWS = 4
"""Kinematics rows with measurement noise: x, y (position sigma) and vx, vy (velocity sigma)."""


class IdealSensor:
    """No latency, no missed detection, no noise."""

    def reset(self, params: BatchParams) -> None:
        """Nothing to set up."""

    def compact(self, index: np.ndarray) -> None:
        """Nothing kept per variant."""

    def observe(self, step: int, t_s: float, visible: np.ndarray, truth: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Every visible VRU, exactly as it is."""
        return visible, truth

    def age_s(self, step: int, dt_s: float) -> np.ndarray | None:
        """Age of the current reports: the ideal sensor reports the present (None: 0 s for every variant)."""
        return None


class RealisticSensor:
    """Latency, frame rate, missed detections and noise, per variant; keyed random draws (`sim/rng.py`).

    State: a ring buffer of the last D = min(max L, steps of the run) + 1 steps' visibility [D, B, K] and true
    kinematics [D, 6, B, K], and the report held since the last frame (detected [B, K], estimate [6, B, K]).
    """

    variant_axes: ClassVar[dict[str, int]] = {"seen": 1, "history": 2, "held_estimate": 1}

    def reset(self, params: BatchParams) -> None:
        """Per-variant settings from `params.sensor`; empty ring buffer and no report held."""
        sensor = params.sensor
        self.seed = params.seed
        self.latency = sensor.latency_steps.copy()
        self.period = sensor.frame_steps.copy()
        self.probability = sensor.detection_probability.copy()
        self.position_sigma_m = sensor.position_sigma_m.copy()
        self.velocity_sigma_mps = sensor.velocity_sigma_mps.copy()
        shape = params.vru_valid.shape
        depth = history_depth(sensor, params.n_steps)
        self.seen = np.zeros((depth, *shape), dtype=bool)
        self.history = np.zeros((depth, 6, *shape))
        self.held = np.zeros(shape, dtype=bool)
        self.held_estimate = np.zeros((6, *shape))

    def compact(self, index: np.ndarray) -> None:
        """Keep only variants `index` (the engine drops stopped ones)."""
        take_members(self, index)

    def observe(self, step: int, t_s: float, visible: np.ndarray, truth: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Store this step's truth; report the frame measured L steps ago if one was, else hold the last."""
        detected = np.empty(visible.shape, dtype=bool)
        estimate = np.empty(truth.shape)
        _observe(
            visible.shape[0],
            step,
            visible,
            truth,
            self.seed,
            self.latency,
            self.period,
            self.probability,
            self.position_sigma_m,
            self.velocity_sigma_mps,
            self.seen,
            self.history,
            self.held,
            self.held_estimate,
            detected,
            estimate,
        )
        return detected, estimate

    def age_s(self, step: int, dt_s: float) -> np.ndarray:
        """Age of each variant's current report [B], s: steps since the frame it describes was measured
        (latency plus the time the report has been held since its frame)."""
        since = np.maximum(step - self.latency, 0)
        measured = (since // self.period) * self.period
        return (step - measured) * dt_s


@batch_kernel
def _observe(
    step,
    visible,
    truth,
    seed,
    latency,
    period,
    probability,
    position_sigma,
    velocity_sigma,
    seen,
    history,
    held,
    held_estimate,
    detected,
    estimate,
):  # pragma: no cover (compiled)
    for b in prange(visible.shape[0]):
        observe_variant(
            b,
            step,
            visible,
            truth,
            seed,
            latency,
            period,
            probability,
            position_sigma,
            velocity_sigma,
            seen,
            history,
            held,
            held_estimate,
            detected,
            estimate,
        )


@njit(cache=True, inline="always")
def observe_variant(
    b,
    step,
    visible,
    truth,
    seed,
    latency,
    period,
    probability,
    position_sigma,
    velocity_sigma,
    seen,
    history,
    held,
    held_estimate,
    detected,
    estimate,
):  # pragma: no cover (compiled)
    """`_observe` for variant b (`slot` = step % depth of the ring buffer)."""
    K = visible.shape[1]
    depth = seen.shape[0]
    slot = step % depth
    for k in range(K):
        seen[slot, b, k] = visible[b, k]
        for row in range(6):
            history[slot, row, b, k] = truth[row, b, k]
    measured = step - latency[b]  # the step whose frame would be reported now
    if measured < 0:  # nothing reported yet: the oldest truth (step 0), flagged not detected
        for k in range(K):
            held[b, k] = False
            for row in range(6):
                held_estimate[row, b, k] = history[0, row, b, k]
    elif measured % period[b] == 0:  # a new frame: detection draw and noise keyed by its step
        old = measured % depth
        for k in range(K):
            held[b, k] = seen[old, b, k] and uniform(seed[b], measured, STREAM_SENSOR_DETECT, k) < probability[b]
            for row in range(6):
                held_estimate[row, b, k] = history[old, row, b, k]
            for axis in range(NOISY_ROWS):
                sigma = position_sigma[b] if axis < 2 else velocity_sigma[b]
                if sigma > 0.0:
                    z = normal(seed[b], measured, STREAM_SENSOR_NOISE, NOISY_ROWS * k + axis)
                    held_estimate[axis, b, k] += sigma * z
    for k in range(K):
        detected[b, k] = held[b, k]
        for row in range(6):
            estimate[row, b, k] = held_estimate[row, b, k]


def all_ideal(params: BatchParams) -> bool:
    """Whether every variant's sensor is ideal (`SensorParams.ideal`)."""
    return bool(params.sensor.ideal.all())


BUILTIN_SENSOR_MODELS = ("ideal", "realistic")
"""The registered names of the built-in sensor models (the compiled step computes exactly these)."""
register_sensor_model(BUILTIN_SENSOR_MODELS[0], all_ideal, IdealSensor, before=None)
register_sensor_model(BUILTIN_SENSOR_MODELS[1], lambda params: True, RealisticSensor, before=None)


def make_sensor_model(params: BatchParams) -> SensorModel:
    """The sensor model of a batch: the first registered one that applies (ideal when every variant's sensor is:
    bit-identical to the paper's; else realistic)."""
    return sensor_model_entry(params).factory()
