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
"""

from __future__ import annotations

import math

import numpy as np

from vrusim.geometry.contact import clearance_local, to_local
from vrusim.geometry.path_table import locate_point
from vrusim.kernels import njit

TTC_STEP_S = 0.05
"""Sampling step of the route TTC, s."""


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
    ex, ey, tx, ty, _ = locate_point(route, offset, rear_station)
    reach = (speed + vru_speed) * horizon + rear_to_centre + half_length + half_width + radius
    if math.hypot(x - ex, y - ey) > reach:
        return np.inf
    count = math.ceil(horizon / TTC_STEP_S - 1e-9)
    previous = np.inf
    for j in range(count + 1):
        t = j * TTC_STEP_S
        if j > 0:
            ex, ey, tx, ty, _ = locate_point(route, offset, rear_station + speed * t)
        cx, cy = ex + rear_to_centre * tx, ey + rear_to_centre * ty
        moving = min(t, stop_s)
        travel = moving * (1.0 - 0.5 * decel * moving / vru_speed) if braking else t  # distance / speed, s
        lx, ly = to_local(cx, cy, tx, ty, x + vx * travel, y + vy * travel)
        clearance = clearance_local(lx, ly, half_length, half_width, radius)[0]
        if clearance <= 0.0:
            if j == 0:
                return 0.0
            contact = t - TTC_STEP_S + TTC_STEP_S * previous / (previous - clearance)
            return contact if contact <= horizon else np.inf
        previous = clearance
    return np.inf
