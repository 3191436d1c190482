"""Batch state: plain arrays, first axis = variant, second = VRU slot. SI units."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from vrusim.sim.params import BatchParams


@dataclass
class EgoState:
    """Kinematic-bicycle state of B egos; the reference point is the rear-axle centre."""

    x_m: np.ndarray
    y_m: np.ndarray
    heading_x: np.ndarray
    heading_y: np.ndarray
    speed_mps: np.ndarray
    accel_mps2: np.ndarray
    """Acceleration achieved over the last step, m/s^2."""
    actuator_mps2: np.ndarray
    """Actuator output after lag and jerk limit, m/s^2."""
    station_m: np.ndarray
    """Rear-axle station along the route, m."""
    curvature_per_m: np.ndarray
    lateral_error_m: np.ndarray
    """Rear-axle offset from the route at the start of the last step, m (left positive)."""
    front_x_m: np.ndarray
    """Centre of the front bumper, m (derived from the pose, kept up to date by the dynamics)."""
    front_y_m: np.ndarray
    centre_x_m: np.ndarray
    """Centre of the ego rectangle, m (derived from the pose)."""
    centre_y_m: np.ndarray


KINEMATICS = ("x_m", "y_m", "vx_mps", "vy_mps", "ax_mps2", "ay_mps2")
"""Rows of a VRU kinematics stack [6, B, K]: position, velocity and acceleration, world frame, SI units."""


@dataclass
class VruState:
    """Path-constrained point masses, [B, K]. `kinematics` [6, B, K] stacks the rows of `KINEMATICS`."""

    variant_axes: ClassVar[dict[str, int]] = {"kinematics": 1}

    started: np.ndarray
    started_at_s: np.ndarray
    """Time the trigger fired, s (inf before)."""
    station_m: np.ndarray
    speed_mps: np.ndarray
    kinematics: np.ndarray
    ego_stopped_at_s: np.ndarray
    """For a trigger on the ego's standstill: when the ego last came to a standstill, s (inf: it is moving)."""

    @property
    def x_m(self) -> np.ndarray:
        return self.kinematics[0]

    @property
    def y_m(self) -> np.ndarray:
        return self.kinematics[1]

    @property
    def vx_mps(self) -> np.ndarray:
        return self.kinematics[2]

    @property
    def vy_mps(self) -> np.ndarray:
        return self.kinematics[3]

    @property
    def ax_mps2(self) -> np.ndarray:
        """Acceleration along the path over the last step, as a world-frame vector, m/s^2."""
        return self.kinematics[4]

    @property
    def ay_mps2(self) -> np.ndarray:
        return self.kinematics[5]


def initial_ego(params: BatchParams) -> EgoState:
    """Egos at the start of their routes, at their start speed."""
    zeros = np.zeros(params.size)
    x, y, tx, ty, _ = params.routes.locate(params.route_offset, zeros)
    return EgoState(
        x,
        y,
        tx,
        ty,
        params.start_speed_mps.copy(),
        zeros.copy(),
        zeros.copy(),
        zeros.copy(),
        zeros.copy(),
        zeros.copy(),
        x + params.rear_to_front_m * tx,
        y + params.rear_to_front_m * ty,
        x + params.rear_to_centre_m * tx,
        y + params.rear_to_centre_m * ty,
    )


def initial_vrus(params: BatchParams) -> VruState:
    """VRUs at the start of their paths, at their initial speed (usually at rest)."""
    zeros = np.zeros(params.vru_valid.shape)
    x, y, tx, ty, _ = params.vru_paths.locate(params.vru_path_offset, zeros)
    speed = params.vru_initial_speed_mps.copy()
    kinematics = np.zeros((len(KINEMATICS), *zeros.shape))
    kinematics[0], kinematics[1] = x, y
    kinematics[2], kinematics[3] = speed * tx, speed * ty
    never = np.full(zeros.shape, np.inf)
    return VruState(np.zeros(zeros.shape, dtype=bool), never, zeros.copy(), speed, kinematics, never.copy())
