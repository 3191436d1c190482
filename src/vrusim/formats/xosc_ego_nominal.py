"""The ego's nominal longitudinal motion, in closed form: its route station (m) and speed (m/s) over time.

Nominal = what the `none` planner drives: without `ego.driver` the start speed held (constant speed; the
import requires it to equal the cruise speed), with a driver its phases in order, each at constant acceleration
`accel_mps2` toward its target and then holding it (`vrusim.sim.driver`; no jerk limit and no actuator lag, the
import's defaults). A phase starts at its time or route station once the previous one runs. The engine latches a
phase at the first step start at or after that moment, so a phase that starts on a route station may begin up to
one time step later there than here.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass

from vrusim.scenario.schema import Ego

MAX_SEGMENTS = 64
"""Constant-acceleration segments followed at most (a driver has at most 8 phases: two segments each)."""
_EPS = 1e-9


@dataclass(frozen=True)
class Segment:
    """Constant acceleration `accel_mps2` from time `t_s`, station `s_m`, speed `v_mps`, for `duration_s` (inf: on)."""

    t_s: float
    s_m: float
    v_mps: float
    accel_mps2: float
    duration_s: float

    def reach(self, station_m: float) -> float | None:
        """The first time into this segment (s) when the station is `station_m`, or None when it is not reached."""
        gap = station_m - self.s_m
        if gap <= _EPS:
            return 0.0 if gap >= -_EPS else None
        v, a = self.v_mps, self.accel_mps2
        if abs(a) < 1e-15:
            tau = gap / v if v > 0 else math.inf
        else:
            disc = v * v + 2.0 * a * gap
            if disc < 0.0:
                return None
            tau = gap / (0.5 * (v + math.sqrt(disc)))  # the smaller root, stable for small a
        return tau if tau <= self.duration_s + _EPS else None

    def at(self, tau_s: float) -> tuple[float, float]:
        """(station m, speed m/s) `tau_s` into the segment."""
        return (
            self.s_m + self.v_mps * tau_s + 0.5 * self.accel_mps2 * tau_s * tau_s,
            self.v_mps + self.accel_mps2 * tau_s,
        )


class EgoNominal:
    """The nominal motion of `ego` (forward; no driver: the start speed held)."""

    def __init__(self, ego: Ego) -> None:
        self.segments = list(_segments(ego))

    def time_at_station(self, station_m: float) -> tuple[float, float] | None:
        """(time s, speed m/s) when the ego's rear axle first reaches route station `station_m`; None: never."""
        for segment in self.segments:
            tau = segment.reach(station_m)
            if tau is not None:
                return segment.t_s + tau, segment.at(tau)[1]
        return None

    def station_at_time(self, t_s: float) -> float:
        """The route station (m) at time `t_s` >= 0."""
        for segment in self.segments:
            if t_s <= segment.t_s + segment.duration_s:
                return segment.at(max(t_s - segment.t_s, 0.0))[0]
        last = self.segments[-1]
        return last.at(last.duration_s)[0]


def _segments(ego: Ego) -> Iterator[Segment]:
    t, s, v = 0.0, 0.0, ego.start_speed_mps
    if ego.driver is None:
        yield Segment(t, s, v, 0.0, math.inf)
        return
    phases = ego.driver.phases
    running, goal, rate = -1, 0.0, ego.max_decel_mps2
    for _ in range(MAX_SEGMENTS):
        while running + 1 < len(phases) and _started(phases[running + 1], t, s):
            running += 1
            goal = phases[running].target_speed_mps
            rate = min(phases[running].accel_mps2, _limit(ego, goal, v))
        accel = 0.0 if abs(goal - v) < _EPS else math.copysign(rate, goal - v)
        duration = abs(goal - v) / rate if accel else math.inf
        if running + 1 < len(phases):
            phase = phases[running + 1]
            if phase.at_time_s is not None:
                duration = min(duration, max(phase.at_time_s - t, 0.0))
            else:
                until = Segment(t, s, v, accel, duration).reach(phase.ego_route_m or 0.0)
                duration = min(duration, until) if until is not None else duration
        segment = Segment(t, s, v, accel, duration)
        yield segment
        if math.isinf(duration):
            return
        s, v = segment.at(duration)
        t, v = t + duration, (goal if abs(v - goal) < 1e-9 else v)
    raise ValueError("the ego's driver schedule has too many segments")  # pragma: no cover (at most 8 phases)


def _started(phase, t_s: float, s_m: float) -> bool:  # type: ignore[no-untyped-def]
    if phase.at_time_s is not None:
        return t_s >= phase.at_time_s - _EPS
    return s_m >= phase.ego_route_m - _EPS


def _limit(ego: Ego, goal_mps: float, v_mps: float) -> float:
    """The ego's own limit for a change toward `goal_mps` (the engine clips the driver's request to it)."""
    return ego.max_accel_mps2 if goal_mps >= v_mps else ego.max_decel_mps2
