"""What the onboard sensor reports, given which VRUs its sector sees: the ideal sensor passes the truth on.

A sensor model turns the geometric visibility of this step (`sensing.sense`) and the true VRU kinematics into
the sensor's report: which VRUs it detects and their estimated kinematics. The ideal model (the paper's
assumption) reports every visible VRU at once and exactly. Realistic models (latency, missed detections,
noise) implement the same two methods; `make_sensor_model` picks one from the batch's parameters.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np

from vrusim.sim.batch import BatchParams


class SensorModel(Protocol):
    """Turns visibility into detections."""

    def reset(self, params: BatchParams) -> None: ...

    def observe(self, step: int, t_s: float, visible: np.ndarray, truth: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(detected [B, K], estimated kinematics [6, B, K]) from this step's visibility and true kinematics."""
        ...


class IdealSensor:
    """No latency, no missed detection, no noise."""

    def reset(self, params: BatchParams) -> None:
        """Nothing to set up."""

    def observe(self, step: int, t_s: float, visible: np.ndarray, truth: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Every visible VRU, exactly as it is."""
        return visible, truth


def make_sensor_model(params: BatchParams) -> SensorModel:
    """The sensor model of a batch."""
    return IdealSensor()
