"""VRU motion: point masses driven along their prescribed paths by a force toward the top speed.

Along the path, acceleration a = clip((v_target - v) / max(tau, dt), -a_max, a_max): with tau = 0 the VRU
accelerates at a_max from rest and holds its top speed exactly (Euro NCAP targets); tau > 0 gives the
exponential approach of the social-force driving term (Helbing & Molnár 1995). Once triggered, a VRU follows
its profile open-loop: it never reacts to the ego.
"""

from __future__ import annotations

import numpy as np

from vrusim.sim.batch import TRIGGER_DISTANCE, TRIGGER_TIME, BatchParams
from vrusim.sim.state import VruState


def triggered(params: BatchParams, t_s: float, front_x: np.ndarray, front_y: np.ndarray,
              ego_speed: np.ndarray) -> np.ndarray:
    """Which VRUs' start conditions hold at time t_s, given the ego's front-bumper position and speed. [B, K]"""
    dx = params.trigger_x_m - front_x[:, None]
    dy = params.trigger_y_m - front_y[:, None]
    distance = np.sqrt(dx * dx + dy * dy)
    by_time = t_s >= params.trigger_value - 1e-9
    by_distance = distance <= params.trigger_value
    by_arrival = distance <= params.trigger_value * ego_speed[:, None]
    kind = params.trigger_kind
    return np.where(kind == TRIGGER_TIME, by_time, np.where(kind == TRIGGER_DISTANCE, by_distance, by_arrival))


def step_vrus(params: BatchParams, vrus: VruState, started: np.ndarray) -> VruState:
    """Advance every VRU by one time step."""
    dt = params.dt_s
    target = np.where(started, params.vru_top_speed_mps, 0.0)
    tau = np.maximum(params.vru_tau_s, dt)
    accel = np.clip((target - vrus.speed_mps) / tau, -params.vru_max_accel_mps2, params.vru_max_accel_mps2)
    speed = vrus.speed_mps + accel * dt
    station = vrus.station_m + (vrus.speed_mps + speed) * (0.5 * dt)
    x, y, tx, ty, _ = params.vru_paths.locate(params.vru_path_offset, station)
    return VruState(started, station, speed, x, y, speed * tx, speed * ty)
