"""Predicted VRU occupancy of the ego's route corridor, and the accelerations that keep the ego out of it.

A VRU is predicted over a horizon on a straight line along its current velocity (`constant_velocity`), or
along its declared path (`path`; the planner is then told the VRU's intent). Its speed along that line is the
current speed (the nominal profile) and, with `speed_envelope`, for a VRU speeding up or slowing down also the
current speed changed at its current along-track acceleration (stopping at 0, never reversing). The planner
honours both profiles: the VRU may arrive as early as the faster one says and leave as late as the slower one.

Every predicted position (every `step_s`, from now to the horizon) is projected onto the ego route (Frenet
frame: station s, lateral offset e). Between two samples e is taken as linear in time, which gives the
exact sub-interval in which the VRU's centre is within the corridor |e| <= h (h = ego half width w + VRU
radius r + margin). Each end of such a sub-interval is an **occupancy point** (tau s from now, station s).
Relative to the ego's front bumper at station s_f, the VRU's near edge is where its circle first reaches into
the strip the ego body sweeps, D = s - sqrt(r^2 - d^2) - s_f with d = min(max(|e| - w, 0), r), and its far edge
is F = s + r - s_f (m along the route).

For an occupancy point to be reached only after `tau` s, the largest constant acceleration with which the
front bumper travels at most D metres in tau seconds (v its speed; it never reverses) is

    a_lin = 2 (D - v tau) / tau^2                 if v + a_lin tau >= 0 (still moving at tau)
    a     = -v^2 / (2 D)                          otherwise (it must stop within D)

(-inf when D <= 0 and the ego moves); a positive a_lin is relaxed by the cap at the cruise speed
(`admissible_accel`). The gentlest deceleration that keeps the ego out of every occupancy point is minus the
smallest of these.
"""

from __future__ import annotations

import math

import numpy as np

from vrusim.geometry.path_table import locate_point, nearest_station, project_from, project_point
from vrusim.kernels import njit

CONSTANT_VELOCITY, PATH = 0, 1
PROJECTION_ITERATIONS = 3
"""Newton steps per predicted sample, warm-started from the previous sample's foot point (whose evaluation of the
route is reused: `project_from`)."""
FOOT_TOLERANCE_M = 0.5
"""A projection whose residual along the route exceeds this did not find a foot point (e.g. before the route
start); the sample then counts as outside the corridor."""


@njit(cache=True, inline="always")
def admissible_accel(speed, tau, distance, top_speed):  # pragma: no cover (compiled)
    """Largest constant acceleration (m/s^2) with which the ego covers at most `distance` m within `tau` s.

    The ego never reverses, and it accelerates no further than `top_speed` (its cruise speed); inf when even
    driving on at the higher of `speed` and `top_speed` keeps it within `distance`.
    """
    if distance <= 0.0:
        return -np.inf if speed > 0.0 else 0.0
    if tau <= 0.0:
        return np.inf
    a = 2.0 * (distance - speed * tau) / (tau * tau)
    if a < 0.0:
        return a if speed + a * tau >= 0.0 else -speed * speed / (2.0 * distance)
    if speed + a * tau <= top_speed:
        return a
    if top_speed * tau <= distance:
        return np.inf
    return (top_speed - speed) ** 2 / (2.0 * (top_speed * tau - distance))


@njit(cache=True, inline="always")
def travelled(speed, accel, t):  # pragma: no cover (compiled)
    """Distance covered in t s from `speed` at constant `accel`, stopping at zero speed (never reversing)."""
    if accel < 0.0 and speed + accel * t < 0.0:
        return speed * speed / (-2.0 * accel)
    return speed * t + 0.5 * accel * t * t


@njit(cache=True, inline="always")
def predicted_position(kind, vru_path, vru_offset, x, y, ux, uy, path_station, distance):  # pragma: no cover
    """Position after moving `distance` m: along (ux, uy) from (x, y), or along the declared path from its station."""
    if kind == PATH:
        px, py, _, _, _ = locate_point(vru_path, vru_offset, path_station + distance)
        return px, py
    return x + ux * distance, y + uy * distance


@njit(cache=True, inline="always")
def _corridor_part(e0, e1, half):  # pragma: no cover (compiled)
    """Fractions [f_lo, f_hi] of a step in which |e0 + (e1 - e0) f| <= half; f_lo > f_hi when never inside."""
    lo, hi = 0.0, 1.0
    de = e1 - e0
    if de == 0.0:
        return (0.0, 1.0) if abs(e0) <= half else (1.0, 0.0)
    a, b = (-half - e0) / de, (half - e0) / de
    lo, hi = max(lo, min(a, b)), min(hi, max(a, b))
    return lo, hi


@njit(cache=True)
def occupancy_bounds(
    route,
    route_offset,
    route_station,
    kind,
    vru_path,
    vru_offset,
    path_station,
    x,
    y,
    ux,
    uy,
    speed,
    accel,
    horizon,
    step,
    half_width,
    corridor_margin,
    radius,
    front_station,
    ego_speed,
    clear_length,
    pass_margin,
    plan,
    out,
):  # pragma: no cover (compiled)
    """Fold one speed profile of one VRU into `out` (updated in place).

    out[0]: 1 if any occupancy point ahead of the front bumper was found;
    out[1]: 1 while the ego, at its current speed, clears every point (its rear bumper past F) at least
    `pass_margin` s before the VRU gets there (start it at 1);
    out[2]: smallest admissible acceleration over the points, each to be reached `margin` s after the VRU and
    `gap` m short of its near edge, m/s^2. `plan` = (margin s, gap m, delay s, distance m, speed m/s, top speed
    m/s): the plan starts after `delay` s, when the ego will have covered `distance` m and will drive at
    `speed` (see `plan_start`); it accelerates no further than `top speed`;
    out[3]: latest occupancy time, s (the VRU's predicted clearing time; -inf when none);
    out[4]: as out[2] for a plan that starts now (no delay).

    The near edge D is where the VRU's circle first reaches into the strip the ego body sweeps (half width w):
    at lateral offset e, `s - sqrt(r^2 - d^2)` with d = min(max(|e| - w, 0), r) (m along the route).
    """
    margin, gap, delay, ahead, plan_speed, top_speed = plan
    half = half_width + radius + corridor_margin
    count = math.floor(horizon / step + 1e-9)
    s_prev = route_station
    fx, fy, tx, ty, kappa = locate_point(route, route_offset, s_prev)  # the route at s_prev, sample to sample
    e_prev, ok_prev, t_prev = 0.0, False, 0.0
    for i in range(count + 1):
        t = i * step
        px, py = predicted_position(kind, vru_path, vru_offset, x, y, ux, uy, path_station, travelled(speed, accel, t))
        s, fx, fy, tx, ty, kappa = project_from(
            route, route_offset, s_prev, fx, fy, tx, ty, kappa, px, py, PROJECTION_ITERATIONS
        )
        residual = (px - fx) * tx + (py - fy) * ty
        ok = abs(residual) <= FOOT_TOLERANCE_M
        e = tx * (py - fy) - ty * (px - fx)
        if i == 0:
            lo, hi = (0.0, 0.0) if (ok and abs(e) <= half) else (1.0, 0.0)
        elif ok and ok_prev:
            lo, hi = _corridor_part(e_prev, e, half)
        else:
            lo, hi = 1.0, 0.0
        if lo <= hi:
            for f in (lo, hi):
                tau = t_prev + f * (t - t_prev) if i > 0 else 0.0
                station = s_prev + f * (s - s_prev) if i > 0 else s
                lateral = e_prev + f * (e - e_prev) if i > 0 else e
                inset = min(max(abs(lateral) - half_width, 0.0), radius)
                near = station - math.sqrt(radius * radius - inset * inset) - front_station
                far = station + radius - front_station
                if far < 0.0:
                    continue  # wholly behind the front bumper: braking cannot help
                out[0] = 1.0
                if ego_speed * (tau - pass_margin) - clear_length < far:
                    out[1] = 0.0
                out[2] = min(out[2], admissible_accel(plan_speed, tau + margin - delay, near - gap - ahead, top_speed))
                out[3] = max(out[3], tau)
                out[4] = min(out[4], admissible_accel(ego_speed, tau + margin, near - gap, top_speed))
        s_prev, e_prev, ok_prev, t_prev = s, e, ok, t


@njit(cache=True, inline="always")
def plan_start(speed, command, plan, jerk):  # pragma: no cover (compiled)
    """Where a plan starts when the command must first ramp from `command` down to `plan` at `jerk`.

    The ramp is replaced by a step half-way through it: the ego keeps accelerating at `command` for
    delay = max(command - plan, 0) / (2 jerk) s. Returns (delay s, distance covered m, speed then m/s).
    """
    delay = max(command - plan, 0.0) / (2.0 * jerk)
    return delay, travelled(speed, command, delay), max(speed + command * delay, 0.0)


@njit(cache=True, inline="always")
def path_station_of(vru_path, vru_offset, was_known, previous, x, y):  # pragma: no cover (compiled)
    """Station of (x, y) on the VRU's declared path: Newton from `previous`, or a global search for a new track."""
    guess = previous if was_known else nearest_station(vru_path, vru_offset, x, y)
    station, _, _, tx, ty, _ = project_point(vru_path, vru_offset, guess, x, y, 2)
    return station, tx, ty
