"""What a planner sees each step: the ego's own state and the VRUs detected by the sensor and/or V2X."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

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
    shape = sensed.shape
    detected, source = np.empty(shape, dtype=bool), np.empty(shape, dtype=np.int8)
    out = np.empty((5, *shape))
    _fuse(
        sensed,
        truth_x,
        truth_y,
        truth_vx,
        truth_vy,
        v2x.received,
        v2x.x_m,
        v2x.y_m,
        v2x.vx_mps,
        v2x.vy_mps,
        v2x.age_s,
        detected,
        source,
        out,
    )
    return detected, source, out[0], out[1], out[2], out[3], out[4]


@njit(cache=True)
def _fuse(
    sensed, tx, ty, tvx, tvy, received, mx, my, mvx, mvy, mage, detected, source, out
):  # pragma: no cover (compiled)
    B, K = sensed.shape
    for b in range(B):
        for k in range(K):
            detected[b, k] = sensed[b, k] or received[b, k]
            source[b, k] = (SOURCE_SENSOR if sensed[b, k] else 0) + (SOURCE_V2X if received[b, k] else 0)
            if sensed[b, k]:
                out[0, b, k], out[1, b, k], out[2, b, k], out[3, b, k], out[4, b, k] = (
                    tx[b, k],
                    ty[b, k],
                    tvx[b, k],
                    tvy[b, k],
                    0.0,
                )
            else:
                out[0, b, k], out[1, b, k], out[2, b, k], out[3, b, k], out[4, b, k] = (
                    mx[b, k],
                    my[b, k],
                    mvx[b, k],
                    mvy[b, k],
                    mage[b, k],
                )
