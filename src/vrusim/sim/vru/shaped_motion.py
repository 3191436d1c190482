"""The compiled step of the shaped VRU motion models `cubic` and `sinusoidal` (`vrusim.sim.vru.shaped`).

Triggers fire as for `point_mass` (the shared `vrusim.sim.vru.triggers`): checked at step starts, a time or route
trigger backs the start up to the instant inside the last step when its condition was met. From the start the speed is a
closed-form function of the time since the start: the change from the initial to the top speed over
T = |v1 - v0| / a (a: the mean rate, `max_accel_mps2`), then, `brake_after_s` after the start (exactly, also inside
a step), the same shape from the speed then to 0 over v_b / the mean deceleration. The station advances by the
exact integral of that speed over the step; the reported acceleration is the exact value at the step's end.
"""

from __future__ import annotations

import math

import numpy as np

from vrusim.geometry.path_table import locate_point
from vrusim.kernels import batch_kernel, njit, prange
from vrusim.sim.params import BatchParams
from vrusim.sim.state import VruState
from vrusim.sim.vru.registry import attach_vru_step
from vrusim.sim.vru.shaped import SHAPE_CODES
from vrusim.sim.vru.triggers import fire_trigger

_CUBIC = SHAPE_CODES["cubic"]


@njit(cache=True, _nrt=False)
def _fraction(shape, s):  # pragma: no cover (compiled)
    """(h(s), h'(s), integral of h from 0 to s) of the shape (0 <= s <= 1)."""
    if shape == _CUBIC:
        return s * s * (3.0 - 2.0 * s), 6.0 * s * (1.0 - s), s**3 - 0.5 * s**4
    return (
        0.5 * (1.0 - math.cos(math.pi * s)),
        0.5 * math.pi * math.sin(math.pi * s),
        0.5 * (s - math.sin(math.pi * s) / math.pi),
    )


@njit(cache=True, _nrt=False)
def _change(shape, v0, v1, duration, u):  # pragma: no cover (compiled)
    """(speed, acceleration, distance) `u` s into a shaped change from v0 to v1 over `duration` s (held after)."""
    if u >= duration:
        return v1, 0.0, 0.5 * (v0 + v1) * duration + v1 * (u - duration)
    h, slope, area = _fraction(shape, u / duration)
    return v0 + (v1 - v0) * h, (v1 - v0) * slope / duration, v0 * u + (v1 - v0) * duration * area


@njit(cache=True, _nrt=False)
def shaped_profile(shape, v0, v1, rate, brake_after, brake_rate, tau):  # pragma: no cover (compiled)
    """(speed m/s, acceleration m/s^2, distance m) `tau` s after the start: v0 -> v1 at mean `rate`, and from
    `brake_after` s on to 0 at mean `brake_rate` (none when `brake_after` is inf or `brake_rate` 0)."""
    duration = abs(v1 - v0) / rate if v1 != v0 else 0.0
    if tau <= brake_after or brake_rate <= 0.0:
        return _change(shape, v0, v1, duration, tau)
    vb, _, db = _change(shape, v0, v1, duration, brake_after)
    speed, accel, distance = _change(shape, vb, 0.0, vb / brake_rate, tau - brake_after)
    return speed, accel, db + distance


def _advance_with(shape: int):
    def advance_vrus(
        params: BatchParams,
        vrus: VruState,
        t_s: float,
        front_x: np.ndarray,
        front_y: np.ndarray,
        ego_speed: np.ndarray,
        ego_station: np.ndarray,
    ) -> None:
        """Fire triggers from the ego state at t_s, then advance every VRU by one step (in place)."""
        _advance(
            params.size,
            shape,
            params.vru_paths.arrays,
            params.vru_path_offset,
            params.trigger_kind,
            params.trigger_value,
            params.trigger_x_m,
            params.trigger_y_m,
            params.vru_top_speed_mps,
            params.vru_max_accel_mps2,
            params.vru_initial_speed_mps,
            params.vru_brake_after_s,
            params.vru_brake_decel_mps2,
            params.dt_s,
            t_s,
            front_x,
            front_y,
            ego_speed,
            ego_station,
            vrus.started,
            vrus.started_at_s,
            vrus.station_m,
            vrus.speed_mps,
            vrus.kinematics,
            vrus.ego_stopped_at_s,
        )

    return advance_vrus


@batch_kernel
def _advance(
    shape,
    path,
    offsets,
    kind,
    value,
    point_x,
    point_y,
    top,
    rate,
    initial_speed,
    brake_after,
    brake_rate,
    dt,
    t,
    front_x,
    front_y,
    ego_speed,
    ego_station,
    started,
    started_at,
    station,
    speed,
    kin,
    stopped_at,
):  # pragma: no cover
    B, K = station.shape
    for b in prange(B):
        for k in range(K):
            since = 0.0  # time since the start at this step's start, s
            if not started[b, k]:
                started[b, k], lead = fire_trigger(
                    kind, value, point_x, point_y, b, k, t, front_x, front_y, ego_speed, ego_station, stopped_at
                )
                if started[b, k]:
                    # the profile starts where the trigger was met: back up to that instant at the initial speed
                    lead = min(max(lead, 0.0), dt)
                    started_at[b, k] = t - lead
                    station[b, k] -= speed[b, k] * lead
            else:
                since = t - started_at[b, k]
            if started[b, k]:
                v0, b_after, b_rate = initial_speed[b, k], brake_after[b, k], brake_rate[b, k]
                _, _, before = shaped_profile(shape, v0, top[b, k], rate[b, k], b_after, b_rate, since)
                end = t + dt - started_at[b, k]
                new_speed, accel, after = shaped_profile(shape, v0, top[b, k], rate[b, k], b_after, b_rate, end)
                station[b, k] += after - before
            else:
                new_speed, accel = initial_speed[b, k], 0.0
                station[b, k] += new_speed * dt
            speed[b, k] = new_speed
            px, py, tx, ty, _ = locate_point(path, offsets[b, k], station[b, k])
            kin[0, b, k], kin[1, b, k], kin[2, b, k], kin[3, b, k] = px, py, new_speed * tx, new_speed * ty
            kin[4, b, k], kin[5, b, k] = accel * tx, accel * ty


for _name, _code in SHAPE_CODES.items():
    attach_vru_step(_name, _advance_with(_code))
