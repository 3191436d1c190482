"""Geometry and timing of the exported motion: trajectory vertices and the ego station where a trigger fires.

Trajectories are polylines of world poses (x m, y m, heading rad). The ego's follows its reference point (the
real rear axle) along the exact route (`scenario.paths.path_poses`): line pieces by their end points, arcs and
clothoids every `VERTEX_SPACING_M` (chord error <= spacing^2 / (8 radius): 1 mm on an 8 m radius).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np

from vrusim.formats.xosc_model import OVERRUN_M
from vrusim.geometry.paths import Line, path_poses
from vrusim.interop.osc_entities import ego_reference_pose
from vrusim.scenario.routes import ego_route_spec
from vrusim.scenario.schema import Ego, Scenario, Trigger, Vru

VERTEX_SPACING_M = 0.25
"""Spacing of trajectory vertices on curved route pieces, m."""
TRIGGER_SEARCH_STEP_M = 0.05
"""Station grid on which a distance / time-to-arrival trigger is first located (then refined by bisection), m."""


@dataclass(frozen=True)
class Vertex:
    """A trajectory vertex: world position (m) and heading (rad, counter-clockwise from +x)."""

    x_m: float
    y_m: float
    heading_rad: float


def ego_max_speed_mps(ego: Ego) -> float:
    """Highest speed of the exported (non-reacting) ego, m/s."""
    return max(ego.start_speed_mps, ego.cruise_speed_mps)


def ego_overrun_m(scenario: Scenario) -> float:
    """How far the ego trajectory continues straight past the route end, m: a little when the run stops there,
    else as far as the ego can drive in the whole run."""
    if scenario.sim.stop_at_route_end:
        return OVERRUN_M
    reach = ego_max_speed_mps(scenario.ego) * scenario.sim.duration_s
    return max(reach - scenario.ego.route.length_m, 0.0) + OVERRUN_M


def ego_trajectory(ego: Ego, overrun_m: float) -> tuple[list[Vertex], float]:
    """Vertices of the ego reference point's path, and the initial distance offset along it (m).

    Forward: the route from the start, then `overrun_m` straight on; offset 0. Reversing (straight routes
    only): the line is written in the body's heading from the far end to the start (its vertices face the
    body), and the ego starts at its end: offset = its length, followed at a negative speed.
    """
    if ego.reverse:
        x0, y0, heading = ego_reference_pose(ego)
        total = ego.route.length_m + overrun_m
        back_x, back_y = x0 - total * math.cos(heading), y0 - total * math.sin(heading)
        return [Vertex(back_x, back_y, heading), Vertex(x0, y0, heading)], total
    spec = ego_route_spec(ego)
    stations, start = [0.0], 0.0
    for piece in spec.pieces:
        end = start + piece.length_m
        count = 1 if isinstance(piece, Line) else max(math.ceil(piece.length_m / VERTEX_SPACING_M), 1)
        stations.extend(np.linspace(start, end, count + 1)[1:])
        start = end
    stations.append(start + overrun_m)
    x, y, heading, _ = path_poses(spec, np.array(stations))
    return [Vertex(float(a), float(b), float(h)) for a, b, h in zip(x, y, heading, strict=True)], 0.0


def vru_reach_m(vru: Vru, duration_s: float) -> float:
    """Farthest a VRU can move along its path in the run, m (0: it never moves)."""
    return max(vru.speed_mps, vru.initial_speed_mps) * duration_s


def vru_trajectory(vru: Vru, reach_m: float) -> list[Vertex]:
    """Vertices of a VRU's path (footprint centre): start, waypoints, then straight on to cover `reach_m`."""
    points = [(vru.start.x_m, vru.start.y_m)]
    if vru.path is not None:
        points += [(p.x_m, p.y_m) for p in vru.path]
    else:
        heading = math.radians(vru.heading_deg or 0.0)
        points.append((vru.start.x_m + math.cos(heading), vru.start.y_m + math.sin(heading)))
    length = sum(math.dist(a, b) for a, b in itertools.pairwise(points))
    (ax, ay), (bx, by) = points[-2], points[-1]
    last = math.atan2(by - ay, bx - ax)
    extra = max(reach_m - length, 0.0)
    if vru.path is None:  # the unit step above only gave the direction: replace it
        points[-1] = (ax + max(reach_m, 1.0) * math.cos(last), ay + max(reach_m, 1.0) * math.sin(last))
    elif extra > 0.0:
        points.append((bx + extra * math.cos(last), by + extra * math.sin(last)))
    headings = [math.atan2(b[1] - a[1], b[0] - a[0]) for a, b in itertools.pairwise(points)]
    return [Vertex(x, y, h) for (x, y), h in zip(points, [*headings, headings[-1]], strict=True)]


def _ego_speed_at(ego: Ego, station_m: np.ndarray) -> np.ndarray:
    """Speed of the exported ego at route stations, m/s: from its start speed to cruise at its accel limit
    (decel limit when slowing down)."""
    v0, vc = ego.start_speed_mps, ego.cruise_speed_mps
    if vc >= v0:
        return np.minimum(vc, np.sqrt(v0 * v0 + 2 * ego.max_accel_mps2 * station_m))
    return np.maximum(vc, np.sqrt(np.maximum(v0 * v0 - 2 * ego.max_decel_mps2 * station_m, 0.0)))


def _trigger_gap(ego: Ego, trigger: Trigger, station_m: np.ndarray) -> np.ndarray:
    """Distance of the ego front from the trigger point minus the trigger's limit, m (<= 0: fired)."""
    spec = ego_route_spec(ego)
    x, y, heading, _ = path_poses(spec, station_m)
    ahead = ego.length_m - ego.trailing_overhang_m  # simulated rear axle -> leading edge, as the engine does
    point = trigger.point
    assert point is not None
    distance = np.hypot(x + ahead * np.cos(heading) - point.x_m, y + ahead * np.sin(heading) - point.y_m)
    if trigger.ego_distance_m is not None:
        return distance - trigger.ego_distance_m
    assert trigger.ego_time_to_arrival_s is not None
    return distance - trigger.ego_time_to_arrival_s * _ego_speed_at(ego, station_m)


def trigger_station_m(ego: Ego, trigger: Trigger, search_m: float) -> float | None:
    """Ego route station (m) where a distance or time-to-arrival trigger first fires for the exported,
    non-reacting ego; None if not within `search_m`. The ego's position is a function of its station, so the
    condition "front within d of P" is the condition "travelled distance >= this station"."""
    stations = np.append(np.arange(0.0, search_m, TRIGGER_SEARCH_STEP_M), search_m)
    fired = np.flatnonzero(_trigger_gap(ego, trigger, stations) <= 0.0)
    if len(fired) == 0:
        return None
    index = int(fired[0])
    if index == 0:
        return 0.0
    lo, hi = float(stations[index - 1]), float(stations[index])
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if _trigger_gap(ego, trigger, np.array([mid]))[0] <= 0.0:
            hi = mid
        else:
            lo = mid
    return hi
