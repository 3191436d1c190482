"""A test-only VRU motion model, added from outside the package: a VRU that drifts sideways at constant speed.

`register()` adds it under `vrus[k].motion: drift` (packing and a NumPy step); `unregister()` removes it. No file of
vrusim is edited to add it.
"""

from __future__ import annotations

import numpy as np

from vrusim.sim.vru.registry import VruMotionRow, register_vru_motion, unregister_vru_motion

NAME = "drift"
DRIFT_Y_MPS = 0.5
"""Every drifting VRU moves along +y at this speed from t = 0, whatever its path and trigger, m/s."""


def pack(vru) -> VruMotionRow:
    return VruMotionRow(DRIFT_Y_MPS, 0.0, 0.0, DRIFT_Y_MPS, np.inf, 0.0)


def advance(params, vrus, t_s, front_x, front_y, ego_speed, ego_station) -> None:
    """Move every valid VRU by speed · dt along +y (in place)."""
    step = params.vru_initial_speed_mps * params.dt_s * params.vru_valid
    vrus.kinematics[1] += step  # row 1: y
    vrus.kinematics[3] = np.where(params.vru_valid, params.vru_initial_speed_mps, 0.0)  # row 3: vy
    vrus.speed_mps[...] = vrus.kinematics[3]


def register() -> None:
    register_vru_motion(NAME, pack, advance)


def unregister() -> None:
    unregister_vru_motion(NAME)
