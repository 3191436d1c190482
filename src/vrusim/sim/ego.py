"""Ego dynamics: kinematic bicycle (rear-axle reference) with a path tracker and a longitudinal actuator.

Lateral: the commanded path curvature is the route's curvature (feedforward) plus feedback on the rear axle's
lateral offset e (m, left positive) and heading error (Samson 1995; Rajamani, Vehicle Dynamics and Control,
2nd ed., Sec. 3.2): kappa = kappa_route - k_e * e - k_psi * sin(dpsi), clipped to tan(max_steer) / wheelbase.
In the distance domain the error obeys e'' + k_psi e' + k_e e = 0 whatever the speed.

Longitudinal: the planner's command is clipped to [-max_decel, max_accel], passed through a first-order lag
(time constant `actuator_lag_s`) and a jerk limit. Position advances exactly for constant acceleration within
a step, and the ego stops exactly where v reaches 0 (it never rolls backwards). Heading turns by
kappa * distance; position follows the mid-step heading (rotations: Taylor series for small angles, exact
sine / cosine above 0.05 rad).
"""

from __future__ import annotations

import math

import numpy as np

from vrusim.geometry.path_table import project_point
from vrusim.kernels import batch_kernel, njit, prange
from vrusim.sim.params import BatchParams
from vrusim.sim.state import EgoState


@njit(cache=True, inline="always")
def rotated(hx, hy, angle):  # pragma: no cover (compiled)
    """(hx, hy) rotated by an angle (rad), not renormalised.

    Small angles (|angle| < 0.05 rad, every step of an ordinary run) use a 5th-order Taylor sine / cosine
    (error < 1e-11); larger ones the exact functions. For an angle of ±0 the series gives cosine 1 and sine
    `angle` exactly, which the first branch uses without evaluating it (the same bits).
    """
    if angle == 0.0:
        return hx - angle * hy, angle * hx + hy
    if abs(angle) < 0.05:
        a2 = angle * angle
        c = 1.0 - a2 * (0.5 - a2 * (1.0 / 24.0))
        s = angle * (1.0 - a2 * ((1.0 / 6.0) - a2 * (1.0 / 120.0)))
    else:
        c, s = math.cos(angle), math.sin(angle)
    return c * hx - s * hy, s * hx + c * hy


@njit(cache=True, inline="always")
def rotate(hx, hy, angle):  # pragma: no cover (compiled)
    """Rotate a unit vector by an angle (rad) (`rotated`), renormalised."""
    rx, ry = rotated(hx, hy, angle)
    norm2 = rx * rx + ry * ry
    if norm2 == 1.0:  # already a unit vector (an ego on a straight route along an axis): dividing by 1 is exact
        return rx, ry
    inv = 1.0 / np.sqrt(norm2)
    return rx * inv, ry * inv


def advance_egos(params: BatchParams, ego: EgoState, accel_command: np.ndarray) -> None:
    """Advance every ego by one step under the planner's acceleration command (m/s^2), in place."""
    _advance(
        params.size,
        params.routes.arrays,
        params.route_offset,
        params.lateral_gain,
        params.heading_gain,
        params.max_curvature_per_m,
        params.max_accel_mps2,
        params.max_decel_mps2,
        params.lag_s,
        params.max_jerk_mps3,
        params.dt_s,
        np.ascontiguousarray(accel_command, dtype=float),
        ego.x_m,
        ego.y_m,
        ego.heading_x,
        ego.heading_y,
        ego.speed_mps,
        ego.accel_mps2,
        ego.actuator_mps2,
        ego.station_m,
        ego.curvature_per_m,
        ego.lateral_error_m,
        params.rear_to_front_m,
        params.rear_to_centre_m,
        ego.front_x_m,
        ego.front_y_m,
        ego.centre_x_m,
        ego.centre_y_m,
    )


@batch_kernel
def _advance(
    path,
    offsets,
    k_lat,
    k_head,
    max_kappa,
    max_accel,
    max_decel,
    lag,
    max_jerk,
    dt,
    command,
    x,
    y,
    hx,
    hy,
    speed,
    accel,
    actuator,
    station,
    curvature,
    lateral_error,
    rear_to_front,
    rear_to_centre,
    front_x,
    front_y,
    centre_x,
    centre_y,
):  # pragma: no cover (compiled)
    for b in prange(x.shape[0]):
        ego_variant(
            b,
            path,
            offsets,
            k_lat,
            k_head,
            max_kappa,
            max_accel,
            max_decel,
            lag,
            max_jerk,
            dt,
            command,
            x,
            y,
            hx,
            hy,
            speed,
            accel,
            actuator,
            station,
            curvature,
            lateral_error,
            rear_to_front,
            rear_to_centre,
            front_x,
            front_y,
            centre_x,
            centre_y,
        )


@njit(cache=True, inline="always")
def ego_variant(
    b,
    path,
    offsets,
    k_lat,
    k_head,
    max_kappa,
    max_accel,
    max_decel,
    lag,
    max_jerk,
    dt,
    command,
    x,
    y,
    hx,
    hy,
    speed,
    accel,
    actuator,
    station,
    curvature,
    lateral_error,
    rear_to_front,
    rear_to_centre,
    front_x,
    front_y,
    centre_x,
    centre_y,
):  # pragma: no cover (compiled)
    """`_advance` for variant b."""
    s, px, py, tx, ty, kappa = project_point(path, offsets[b], station[b], x[b], y[b], 1)
    lateral = tx * (y[b] - py) - ty * (x[b] - px)
    sin_heading_error = tx * hy[b] - ty * hx[b]
    turn_rate = kappa - k_lat[b] * lateral - k_head[b] * sin_heading_error
    turn_rate = min(max(turn_rate, -max_kappa[b]), max_kappa[b])
    # longitudinal: clip, lag, jerk limit
    wanted = min(max(command[b], -max_decel[b]), max_accel[b])
    if lag[b] > 0.0:
        wanted = actuator[b] + (wanted - actuator[b]) * min(dt / lag[b], 1.0)
    change = min(max(wanted - actuator[b], -max_jerk[b] * dt), max_jerk[b] * dt)
    act = actuator[b] + change
    v = speed[b]
    v_new = v + act * dt
    if v_new < 0.0:  # stops inside the step
        distance = v * v / (2.0 * max(-act, 1e-12))
        v_new = 0.0
    else:
        distance = (v + v_new) * 0.5 * dt
    turn = turn_rate * distance
    mx, my = rotate(hx[b], hy[b], 0.5 * turn)
    x[b] += distance * mx
    y[b] += distance * my
    hx[b], hy[b] = rotate(hx[b], hy[b], turn)
    accel[b] = (v_new - v) / dt
    speed[b] = v_new
    actuator[b] = act
    station[b] = s + distance
    curvature[b] = turn_rate
    lateral_error[b] = lateral
    front_x[b], front_y[b] = x[b] + rear_to_front[b] * hx[b], y[b] + rear_to_front[b] * hy[b]
    centre_x[b], centre_y[b] = x[b] + rear_to_centre[b] * hx[b], y[b] + rear_to_centre[b] * hy[b]
