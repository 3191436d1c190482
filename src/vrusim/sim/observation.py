"""What a planner sees each step: the ego's own state and the VRUs detected by the sensor and/or V2X."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vrusim.scenario.paths import PathTable
from vrusim.sim.v2x import V2xMessages

SOURCE_SENSOR = 1
"""Bit set in `Observation.source` when the onboard sensor perceives the VRU."""
SOURCE_V2X = 2
"""Bit set in `Observation.source` when a V2X message about the VRU was received."""


@dataclass
class Observation:
    """Planner input for a batch. Ego fields are [B]; VRU fields [B, K]. SI units, world frame.

    A VRU's estimate comes from the sensor when it perceives it, else from the latest V2X message.
    Entries where `detected` is False carry no information and must be ignored.
    """

    t_s: float
    dt_s: float
    # ego (rear-axle reference)
    ego_x_m: np.ndarray
    ego_y_m: np.ndarray
    ego_heading_x: np.ndarray
    ego_heading_y: np.ndarray
    ego_speed_mps: np.ndarray
    ego_accel_mps2: np.ndarray
    ego_station_m: np.ndarray
    cruise_speed_mps: np.ndarray
    rear_to_front_m: np.ndarray
    half_width_m: np.ndarray
    routes: PathTable
    route_offset: np.ndarray
    # detections
    detected: np.ndarray
    source: np.ndarray
    vru_x_m: np.ndarray
    vru_y_m: np.ndarray
    vru_vx_mps: np.ndarray
    vru_vy_mps: np.ndarray
    vru_radius_m: np.ndarray
    vru_age_s: np.ndarray


def fuse(sensed: np.ndarray, truth_x, truth_y, truth_vx, truth_vy, v2x: V2xMessages):
    """Union of sensor and V2X detections: (detected, source bits, x, y, vx, vy, age); sensor wins."""
    detected = sensed | v2x.received
    source = sensed * np.int8(SOURCE_SENSOR) + v2x.received * np.int8(SOURCE_V2X)
    x = np.where(sensed, truth_x, v2x.x_m)
    y = np.where(sensed, truth_y, v2x.y_m)
    vx = np.where(sensed, truth_vx, v2x.vx_mps)
    vy = np.where(sensed, truth_vy, v2x.vy_mps)
    age = np.where(sensed, 0.0, v2x.age_s)
    return detected, source.astype(np.int8), x, y, vx, vy, age
