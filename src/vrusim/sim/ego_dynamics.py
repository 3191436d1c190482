"""Ego dynamics: kinematic bicycle (rear-axle reference) with a path tracker and a longitudinal actuator.

Lateral: the commanded path curvature is the route's curvature (feedforward) plus feedback on the rear axle's
lateral offset e (m, left positive) and heading error (Samson 1995; Rajamani, Vehicle Dynamics and Control,
2nd ed., Sec. 3.2): kappa = kappa_route - k_e * e - k_psi * sin(dpsi), clipped to tan(max_steer) / wheelbase.
In the distance domain the error obeys e'' + k_psi e' + k_e e = 0 whatever the speed.

Longitudinal: the planner's command is clipped to [-max_decel, max_accel], passed through a first-order lag
(time constant `actuator_lag_s`) and a jerk limit. Position advances exactly for constant acceleration within
a step, and the ego stops exactly where v reaches 0 (it never rolls backwards).
"""

from __future__ import annotations

import numpy as np

from vrusim.sim.batch import BatchParams
from vrusim.sim.state import EgoState


def rotate(hx: np.ndarray, hy: np.ndarray, angle: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rotate unit vectors by small angles (rad) without trigonometric calls (5th-order Taylor, renormalised)."""
    a2 = angle * angle
    c = 1.0 - a2 * (0.5 - a2 * (1.0 / 24.0))
    s = angle * (1.0 - a2 * ((1.0 / 6.0) - a2 * (1.0 / 120.0)))
    rx, ry = c * hx - s * hy, s * hx + c * hy
    inv = 1.0 / np.sqrt(rx * rx + ry * ry)
    return rx * inv, ry * inv


def track_route(params: BatchParams, ego: EgoState) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Project the rear axle onto its route; return (station m, lateral error m, commanded curvature 1/m)."""
    station, px, py, tx, ty, kappa = params.routes.project(
        params.route_offset, ego.station_m, ego.x_m, ego.y_m, iterations=1
    )
    lateral = tx * (ego.y_m - py) - ty * (ego.x_m - px)
    sin_heading_error = tx * ego.heading_y - ty * ego.heading_x
    command = kappa - params.lateral_gain * lateral - params.heading_gain * sin_heading_error
    return station, lateral, np.clip(command, -params.max_curvature_per_m, params.max_curvature_per_m)


def actuate(params: BatchParams, actuator: np.ndarray, command: np.ndarray) -> np.ndarray:
    """Actuator output after clipping, first-order lag and jerk limit, m/s^2."""
    dt = params.dt_s
    wanted = np.clip(command, -params.max_decel_mps2, params.max_accel_mps2)
    blend = np.minimum(dt / np.maximum(params.lag_s, 1e-12), 1.0)
    wanted = actuator + (wanted - actuator) * blend
    max_change = params.max_jerk_mps3 * dt
    return actuator + np.clip(wanted - actuator, -max_change, max_change)


def step_ego(params: BatchParams, ego: EgoState, accel_command: np.ndarray) -> EgoState:
    """Advance every ego by one time step under the planner's acceleration command (m/s^2)."""
    dt = params.dt_s
    station, _, curvature = track_route(params, ego)
    actuator = actuate(params, ego.actuator_mps2, accel_command)
    speed = ego.speed_mps
    new_speed = speed + actuator * dt
    stops = new_speed < 0.0
    # exact distance for constant acceleration; when stopping, v^2 / (2 |a|)
    distance = np.where(stops, speed * speed / (2.0 * np.maximum(-actuator, 1e-12)),
                        (speed + new_speed) * (0.5 * dt))
    new_speed = np.maximum(new_speed, 0.0)
    turn = curvature * distance
    mid_x, mid_y = rotate(ego.heading_x, ego.heading_y, 0.5 * turn)
    heading_x, heading_y = rotate(ego.heading_x, ego.heading_y, turn)
    return EgoState(
        x_m=ego.x_m + distance * mid_x,
        y_m=ego.y_m + distance * mid_y,
        heading_x=heading_x,
        heading_y=heading_y,
        speed_mps=new_speed,
        accel_mps2=(new_speed - speed) * (1.0 / dt),
        actuator_mps2=actuator,
        station_m=station + distance,
        curvature_per_m=curvature,
    )
