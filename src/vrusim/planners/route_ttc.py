"""Time to collision along the ego's route, for planners (AEB stages, predictive fallback).

The ego keeps its current speed **along its route** (so a turning ego turns in the prediction; its rectangle is
placed at the route pose of its rear axle, heading along the route tangent there) and each VRU keeps its current
velocity, or, given a braking deceleration, slows along its heading at that rate until it stands still (a braking
lead, Euro NCAP CMRb). The TTC is the first time the rectangle and the VRU's circle touch (clearance <= 0, the exact
rectangle-circle clearance of `vrusim.geometry.contact`). The clearance is evaluated every `TTC_STEP_S` up to a
horizon and the contact time is interpolated linearly between the last two samples.

On a straight route this is the 2-D TTC of `vrusim.geometry.ttc`: exact wherever the clearance changes linearly
in time, e.g. a stationary target met by the front face (TTC = gap / v), and within the interpolation error of
one step otherwise (a VRU met at a corner of the rectangle). A VRU whose relative motion carries it across the
whole rectangle within one step (over 1.8 m / 0.05 s = 36 m/s sideways for a 1.8 m wide car) can be missed.

Samples that cannot touch are skipped, without changing the result. Between two samples the VRU moves at most
its speed × dt, the rear axle at most `speed` × dt along the route, and the rectangle turns by at most the
route's largest segment-to-segment turn per sample spacing crossed (plus one), which moves none of its points
by more than that angle × their distance from the rear axle. So the clearance can shrink by no more than a known
amount per sample, and the samples it cannot reach 0 by are skipped; likewise while the rear axle's distance to
the VRU exceeds the disk holding the rectangle, plus the circle, by more than the closing (no turn needed). The
sample before a contact is evaluated even when it was skipped (the interpolation needs its clearance), so the TTC
is bit-identical to evaluating every sample (`tests/test_route_ttc.py`).
"""

from __future__ import annotations

import math

import numpy as np

from vrusim.geometry.contact import clearance_local, to_local
from vrusim.geometry.path_table import locate_point
from vrusim.kernels import njit

TTC_STEP_S = 0.05
"""Sampling step of the route TTC, s."""


SKIP_MARGIN_M = 1e-6
"""Distance kept in reserve when skipping samples, m: far above the rounding of the distances involved."""


@njit(cache=True, inline="always")
def _sample(
    route,
    offset,
    rear_station,
    speed,
    rear_to_centre,
    half_length,
    half_width,
    x,
    y,
    vx,
    vy,
    decel,
    radius,
    vru_speed,
    stop_s,
    t,
):  # pragma: no cover (compiled)
    """(clearance, rear axle x, y, VRU x, y) at prediction time `t` s."""
    ex, ey, tx, ty, _ = locate_point(route, offset, rear_station + speed * t)
    cx, cy = ex + rear_to_centre * tx, ey + rear_to_centre * ty
    moving = min(t, stop_s)
    travel = moving * (1.0 - 0.5 * decel * moving / vru_speed) if stop_s < np.inf else t  # distance / speed, s
    px, py = x + vx * travel, y + vy * travel
    lx, ly = to_local(cx, cy, tx, ty, px, py)
    return clearance_local(lx, ly, half_length, half_width, radius)[0], ex, ey, px, py


@njit(cache=True)
def route_ttc(
    route, offset, rear_station, speed, rear_to_centre, half_length, half_width, x, y, vx, vy, decel, radius, horizon
):  # pragma: no cover (compiled)
    """TTC (s) of one VRU (position x, y, velocity vx, vy, braking `decel` >= 0 m/s^2 along its velocity until it
    stops, radius) for the ego driving on along its route.

    inf when they do not touch within `horizon` s; 0 when they touch now.
    """
    vru_speed = math.sqrt(vx * vx + vy * vy)
    braking = decel > 0.0 and vru_speed > 0.0
    stop_s = vru_speed / decel if braking else np.inf
    # screen: too far apart to meet within the horizon (the route is no longer than the distance driven)
    ex, ey, _, _, _ = locate_point(route, offset, rear_station)
    reach = (speed + vru_speed) * horizon + rear_to_centre + half_length + half_width + radius
    if math.hypot(x - ex, y - ey) > reach:
        return np.inf
    # bounds for skipping: the rectangle within `corner` m of the rear axle; per sample the rear axle and the VRU
    # get at most `closing` m nearer, the rectangle's points move at most `sweep` m (turn included)
    corner = math.hypot(abs(rear_to_centre) + half_length, half_width)
    disk = corner + radius + SKIP_MARGIN_M
    closing = (abs(speed) + vru_speed) * TTC_STEP_S
    turn = route[7][offset]
    sweep = (abs(speed) * (1.0 + corner * turn * route[5]) + vru_speed) * TTC_STEP_S
    reserve = corner * turn + SKIP_MARGIN_M
    count = math.ceil(horizon / TTC_STEP_S - 1e-9)
    previous, evaluated = np.inf, -1
    j = 0
    while j <= count:
        t = j * TTC_STEP_S
        clearance, ex, ey, px, py = _sample(
            route, offset, rear_station, speed, rear_to_centre, half_length, half_width, x, y, vx, vy, decel, radius,
            vru_speed, stop_s, t,
        )  # fmt: skip
        if clearance <= 0.0:
            if j == 0:
                return 0.0
            if evaluated != j - 1:  # the sample before was skipped: the interpolation needs its clearance
                previous = _sample(
                    route, offset, rear_station, speed, rear_to_centre, half_length, half_width, x, y, vx, vy, decel,
                    radius, vru_speed, stop_s, (j - 1) * TTC_STEP_S,
                )[0]  # fmt: skip
            contact = t - TTC_STEP_S + TTC_STEP_S * previous / (previous - clearance)
            return contact if contact <= horizon else np.inf
        previous, evaluated = clearance, j
        # the next m samples cannot touch while m * closing < gap or m * sweep < clearance - reserve
        gap = math.hypot(px - ex, py - ey) - disk
        if closing <= 0.0 or gap > (count + 1) * closing or clearance - reserve > (count + 1) * sweep:
            break
        skip = max(math.ceil(gap / closing), math.ceil((clearance - reserve) / sweep)) - 1
        j += 1 + max(skip, 0)
    return np.inf
