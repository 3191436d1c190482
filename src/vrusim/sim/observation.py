"""What a planner sees each step: the ego's own state and the VRUs detected by the sensor and/or V2X."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from vrusim.geometry.path_table import PathTable
from vrusim.kernels import batch_kernel, njit, prange
from vrusim.sim.v2x.messages import V2xMessages

SOURCE_SENSOR = 1
"""Bit set in `Observation.source` when the onboard sensor perceives the VRU."""
SOURCE_V2X = 2
"""Bit set in `Observation.source` when a V2X message about the VRU was received."""


@dataclass
class Observation:
    """Planner input for a batch. Ego fields are [B]; VRU fields [B, K]. SI units, world frame.

    A VRU's estimate comes from the sensor when it perceives it, else from this step's V2X message (the
    channel decides what arrives now; keeping older information is the planner's business, e.g. its tracks).
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
    ego_length_m: np.ndarray
    """[B] the ego's length, m: its rear bumper is `ego_length_m - rear_to_front_m` behind the rear axle."""
    routes: PathTable
    route_offset: np.ndarray
    # detections
    detected: np.ndarray
    source: np.ndarray
    vru_estimate: np.ndarray
    """[7, B, K]: x m, y m, vx m/s, vy m/s, ax m/s^2, ay m/s^2, age s of each VRU estimate."""
    vru_radius_m: np.ndarray
    # the driver and the door (docs/low_speed_situations.md); None in hand-built observations: no driver, no door
    driver_accel_mps2: np.ndarray | None = field(default=None)
    """[B] the driver's requested acceleration, m/s^2 (`ego.driver`; 0 without a driver)."""
    driver_idle_accel_mps2: np.ndarray | None = field(default=None)
    """[B] the request with the accelerator released (creeping), m/s^2 (0 without a driver)."""
    driver_accelerator: np.ndarray | None = field(default=None)
    """[B] the driver presses the accelerator pedal (bool)."""
    has_driver: np.ndarray | None = field(default=None)
    """[B] the variant has a driver schedule (bool): without one, planners drive by `cruise_speed_mps`."""
    door_requested: np.ndarray | None = field(default=None)
    """[B] the occupant has operated the door (`ego.door`; bool)."""
    door_angle_rad: np.ndarray | None = field(default=None)
    """[B] the door's opening angle, rad (0: closed or no door)."""

    def driver_request(self) -> tuple[np.ndarray, np.ndarray]:
        """(has_driver [B] bool, driver_accel_mps2 [B]): no driver and zeros where the fields are absent."""
        if self.has_driver is None or self.driver_accel_mps2 is None:
            size = self.ego_speed_mps.shape[0]
            return np.zeros(size, dtype=bool), np.zeros(size)
        return self.has_driver, self.driver_accel_mps2

    @property
    def vru_x_m(self) -> np.ndarray:
        return self.vru_estimate[0]

    @property
    def vru_y_m(self) -> np.ndarray:
        return self.vru_estimate[1]

    @property
    def vru_vx_mps(self) -> np.ndarray:
        return self.vru_estimate[2]

    @property
    def vru_vy_mps(self) -> np.ndarray:
        return self.vru_estimate[3]

    @property
    def vru_ax_mps2(self) -> np.ndarray:
        return self.vru_estimate[4]

    @property
    def vru_ay_mps2(self) -> np.ndarray:
        return self.vru_estimate[5]

    @property
    def vru_age_s(self) -> np.ndarray:
        return self.vru_estimate[6]


def fuse(
    sensed: np.ndarray, sensor_estimate: np.ndarray, v2x: V2xMessages, sensor_age_s: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Union of sensor and V2X detections: (detected [B, K], source bits [B, K], estimate [7, B, K]).

    The estimate stacks x, y, vx, vy, ax, ay (the sensor's estimate [6, B, K] where it detects the VRU, else
    the V2X track's) and the age in s of the information behind it; the sensor wins. Both sources are
    predicted to now at constant velocity: the V2X track by the channel, a delayed sensor report here.
    """
    shape = sensed.shape
    detected, source = np.empty(shape, dtype=bool), np.empty(shape, dtype=np.int8)
    estimate = np.empty((7, *shape))
    sensor_age = np.zeros(shape[0]) if sensor_age_s is None else sensor_age_s
    _fuse(
        shape[0], sensed, sensor_estimate, sensor_age, v2x.received, v2x.kinematics, v2x.age_s, detected, source,
        estimate,
    )  # fmt: skip
    return detected, source, estimate


@batch_kernel
def _fuse(sensed, truth, sensor_age, received, message, age, detected, source, out):  # pragma: no cover (compiled)
    for b in prange(sensed.shape[0]):
        fuse_variant(b, sensed, truth, sensor_age, received, message, age, detected, source, out)


@njit(cache=True, inline="always")
def fuse_variant(b, sensed, truth, sensor_age, received, message, age, detected, source, out):  # pragma: no cover
    """`fuse` for variant b."""
    for k in range(sensed.shape[1]):
        detected[b, k] = sensed[b, k] or received[b, k]
        source[b, k] = (SOURCE_SENSOR if sensed[b, k] else 0) + (SOURCE_V2X if received[b, k] else 0)
        for row in range(6):
            out[row, b, k] = truth[row, b, k] if sensed[b, k] else message[row, b, k]
        if sensed[b, k]:  # a delayed report is predicted to now at constant velocity, like a V2X track
            out[0, b, k] += truth[2, b, k] * sensor_age[b]
            out[1, b, k] += truth[3, b, k] * sensor_age[b]
        out[6, b, k] = sensor_age[b] if sensed[b, k] else age[b, k]
