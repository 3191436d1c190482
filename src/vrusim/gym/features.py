"""The agent's observation: the planner observation flattened into a fixed-size float32 vector per variant.

Layout (`feature_names(K)`): six ego features, then `PER_VRU` features for each of K VRU slots (the scenario's
VRUs in order; slots beyond its VRU count, and VRUs not detected this step, are all zeros except clearance and
TTC, which read their caps). VRU features describe the fused estimate the planner sees (sensor or V2X), never
the ground truth; relative positions are in the ego frame (ISO 8855: x forward along the ego heading, y left)
with the origin at the centre of the ego's front bumper.
"""

from __future__ import annotations

import functools

import numpy as np
from gymnasium import spaces

from vrusim.geometry.contact import clearance_batch
from vrusim.geometry.ttc import ttc_batch
from vrusim.sim.observation import SOURCE_SENSOR, SOURCE_V2X, Observation
from vrusim.sim.params import BatchParams

TTC_CAP_S = 10.0
"""TTC reported for a VRU with no predicted contact, or not detected, s."""
CLEARANCE_CAP_M = 100.0
"""Clearance reported for a VRU farther than this, or not detected, m."""
DEFAULT_VRU_SLOTS = 4
"""VRU slots K of the observation unless told otherwise (a scenario with more VRUs needs a larger K)."""

EGO_FEATURES = (
    ("ego_speed_mps", "ego speed, m/s", 0.0, 100.0),
    ("ego_accel_mps2", "acceleration achieved over the last step, m/s^2", -100.0, 100.0),
    ("ego_station_m", "distance travelled along the route (rear axle), m", -1e4, 1e4),
    ("route_remaining_m", "route length minus station, m", -1e4, 1e4),
    ("cruise_speed_mps", "the scenario's cruise speed, m/s", 0.0, 100.0),
    ("time_remaining_s", "duration minus time, s (the episode is truncated at 0)", 0.0, 3600.0),
)
"""(name, meaning with unit, low, high) of the ego features; values are clipped to [low, high]."""
VRU_FEATURES = (
    ("detected", "1 if the sensor or V2X reports the VRU this step, else 0", 0.0, 1.0),
    ("by_sensor", "1 if the onboard sensor perceives it", 0.0, 1.0),
    ("by_v2x", "1 if a V2X message about it was received", 0.0, 1.0),
    ("rel_x_m", "estimated position ahead of the front bumper centre, ego frame, m", -1e3, 1e3),
    ("rel_y_m", "estimated position left of the front bumper centre, ego frame, m", -1e3, 1e3),
    ("rel_vx_mps", "estimated VRU velocity minus ego velocity, ego x axis, m/s", -200.0, 200.0),
    ("rel_vy_mps", "same, ego y axis, m/s", -200.0, 200.0),
    ("radius_m", "footprint radius, m", 0.0, 10.0),
    ("age_s", "age of the information behind the estimate, s", 0.0, 3600.0),
    ("clearance_m", "gap from the ego rectangle to the estimated footprint, m (<= 0: overlap)", -10.0, CLEARANCE_CAP_M),
    ("ttc_s", "time-to-collision at constant velocities from the estimate, s", 0.0, TTC_CAP_S),
)
"""(name, meaning with unit, low, high) of the features of each VRU slot; clipped to [low, high]."""
PER_VRU = len(VRU_FEATURES)
_NAMES = [feature[0] for feature in VRU_FEATURES]
_CLEARANCE, _TTC = _NAMES.index("clearance_m"), _NAMES.index("ttc_s")


def feature_names(vru_slots: int = DEFAULT_VRU_SLOTS) -> tuple[str, ...]:
    """Name of every element of the observation vector (`vru<k>_<feature>` for VRU slot k)."""
    vru = tuple(f"vru{k}_{feature[0]}" for k in range(vru_slots) for feature in VRU_FEATURES)
    return tuple(feature[0] for feature in EGO_FEATURES) + vru


@functools.cache
def _bounds(vru_slots: int) -> tuple[np.ndarray, np.ndarray]:
    features = EGO_FEATURES + VRU_FEATURES * vru_slots
    low = np.array([f[2] for f in features], dtype=np.float32)
    high = np.array([f[3] for f in features], dtype=np.float32)
    low.flags.writeable = high.flags.writeable = False
    return low, high


def observation_space(vru_slots: int = DEFAULT_VRU_SLOTS) -> spaces.Box:
    """The Box of one observation vector (bounds from `EGO_FEATURES` and `VRU_FEATURES`)."""
    low, high = _bounds(vru_slots)
    return spaces.Box(low.copy(), high.copy(), dtype=np.float32)


def observation_vectors(params: BatchParams, observation: Observation, vru_slots: int) -> np.ndarray:
    """The observation vectors of a batch, float32 [B, 6 + K * PER_VRU]."""
    p, o = params, observation
    B, K = p.size, p.vru_slots
    if vru_slots < K:
        raise ValueError(f"vru_slots={vru_slots} is too small for a scenario with {K} VRUs")
    out = np.zeros((B, len(EGO_FEATURES) + vru_slots * PER_VRU), dtype=np.float32)
    out[:, 0], out[:, 1], out[:, 2] = o.ego_speed_mps, o.ego_accel_mps2, o.ego_station_m
    out[:, 3] = p.route_length_m - o.ego_station_m
    out[:, 4] = o.cruise_speed_mps
    out[:, 5] = np.maximum(p.duration_s - o.t_s, 0.0)
    # writable copies (as the ego's speed below): the argument types the engine's kernels are compiled for, which
    # `vrusim compile` has compiled; a read-only array would compile another version of `ttc_batch`
    hx, hy = o.ego_heading_x.copy(), o.ego_heading_y.copy()
    front_x, front_y = o.ego_x_m + p.rear_to_front_m * hx, o.ego_y_m + p.rear_to_front_m * hy
    dx, dy = o.vru_x_m - front_x[:, None], o.vru_y_m - front_y[:, None]
    ego_vx, ego_vy = o.ego_speed_mps * hx, o.ego_speed_mps * hy
    dvx, dvy = o.vru_vx_mps - ego_vx[:, None], o.vru_vy_mps - ego_vy[:, None]
    centre_x, centre_y = o.ego_x_m + p.rear_to_centre_m * hx, o.ego_y_m + p.rear_to_centre_m * hy
    estimate_x, estimate_y = np.ascontiguousarray(o.vru_x_m), np.ascontiguousarray(o.vru_y_m)
    contact, ttc = np.empty((3, *estimate_x.shape)), np.empty(estimate_x.shape)
    clearance_batch(
        B, centre_x, centre_y, hx, hy, p.half_length_m, p.half_width_m, estimate_x, estimate_y, p.vru_radius_m,
        contact,
    )  # fmt: skip
    clearance = contact[0]
    ttc_batch(
        B, centre_x, centre_y, hx, hy, p.half_length_m, p.half_width_m, o.ego_speed_mps.copy(),
        estimate_x, estimate_y, p.vru_radius_m, np.ascontiguousarray(o.vru_vx_mps), np.ascontiguousarray(o.vru_vy_mps),
        ttc,
    )  # fmt: skip
    seen = o.detected
    columns = (
        seen,
        (o.source & SOURCE_SENSOR) != 0,
        (o.source & SOURCE_V2X) != 0,
        dx * hx[:, None] + dy * hy[:, None],
        -dx * hy[:, None] + dy * hx[:, None],
        dvx * hx[:, None] + dvy * hy[:, None],
        -dvx * hy[:, None] + dvy * hx[:, None],
        o.vru_radius_m,
        o.vru_age_s,
    )
    slots = out[:, len(EGO_FEATURES) :].reshape(B, vru_slots, PER_VRU)
    for index, column in enumerate(columns):
        slots[:, :K, index] = np.where(seen, column, 0.0)
    slots[:, :, _CLEARANCE] = CLEARANCE_CAP_M
    slots[:, :, _TTC] = TTC_CAP_S
    slots[:, :K, _CLEARANCE] = np.where(seen, clearance, CLEARANCE_CAP_M)
    slots[:, :K, _TTC] = np.where(seen, ttc, TTC_CAP_S)
    low, high = _bounds(vru_slots)
    return np.clip(out, low, high, out=out)
