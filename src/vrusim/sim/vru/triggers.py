"""VRU triggers, shared by every compiled VRU motion step: has a VRU's start condition been met at time t?

Conditions (`vrusim.sim.params.TRIGGER_*`): a time; the ego's route station; the ego's speed at most / at least a
value; the ego standing still for a time; the ego's front bumper within a distance, or a time-to-arrival at its
current speed, of a point. Judged on the ego state at a step's start; time, route and stand-still triggers also
say how long ago, inside the last step, the condition was met (`lead`, s), so a profile can start at that instant.
"""

from __future__ import annotations

import numpy as np

from vrusim.kernels import njit
from vrusim.sim.params import (
    TRIGGER_DISTANCE,
    TRIGGER_ROUTE,
    TRIGGER_SPEED_ABOVE,
    TRIGGER_SPEED_BELOW,
    TRIGGER_STANDSTILL,
    TRIGGER_TIME,
)


@njit(cache=True, inline="always")
def fire_trigger(
    kind, value, point_x, point_y, b, k, t, front_x, front_y, ego_speed, ego_station, stopped_at
):  # pragma: no cover (compiled)
    """(met, lead s) of VRU k of variant b at time t (s); `stopped_at` [B, K] (s, inf: moving) keeps when the ego
    last came to a standstill, for stand-still triggers (updated in place)."""
    met, lead = False, 0.0
    if kind[b, k] == TRIGGER_TIME:
        met = t >= value[b, k] - 1e-9
        lead = t - value[b, k]
    elif kind[b, k] == TRIGGER_ROUTE:
        met = ego_station[b] >= value[b, k] - 1e-9
        if ego_speed[b] > 0.0:
            lead = (ego_station[b] - value[b, k]) / ego_speed[b]
    elif kind[b, k] == TRIGGER_SPEED_BELOW:
        met = ego_speed[b] <= value[b, k] + 1e-9
    elif kind[b, k] == TRIGGER_SPEED_ABOVE:
        met = ego_speed[b] >= value[b, k] - 1e-9
    elif kind[b, k] == TRIGGER_STANDSTILL:
        if ego_speed[b] > 1e-9:
            stopped_at[b, k] = np.inf
        elif stopped_at[b, k] == np.inf:
            stopped_at[b, k] = t
        met = t >= stopped_at[b, k] + value[b, k] - 1e-9
        lead = t - stopped_at[b, k] - value[b, k]
    else:
        dx, dy = point_x[b, k] - front_x[b], point_y[b, k] - front_y[b]
        distance = np.sqrt(dx * dx + dy * dy)
        limit = value[b, k] if kind[b, k] == TRIGGER_DISTANCE else value[b, k] * ego_speed[b]
        met = distance <= limit
    return met, lead
