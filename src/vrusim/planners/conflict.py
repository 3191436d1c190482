"""Conflict analysis of detected VRUs against the ego's own route (shared by rule-based planners).

Each VRU track is projected onto the ego route (Frenet frame: station s along the route, lateral offset e,
left positive) and its velocity split into along-route and cross-route parts. Under constant velocity in
that frame, the VRU occupies the ego's corridor (|e| <= ego half width + VRU radius + margin) during a time
window [t_in, t_out]. A VRU *conflicts* with the ego path when it is tracked, ahead of the ego's front bumper,
and its corridor window overlaps [0, horizon]. The distance to it is measured along the route from the front
bumper to the VRU's near edge, at its current position or at its predicted corridor entry, whichever is
nearer (the entry point matters on curved routes). A conflicting VRU in the corridor that moves along the
route faster than `LEAD_SPEED_MPS` (and more along than across) is a *lead* to follow rather than a crossing.

Track memory: a VRU that drops out of detection (for instance out of the sensor sector beside the bumper) is
still considered for `memory_s` seconds at its last detected position, predicted forward at its last detected
velocity.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from vrusim.scenario.paths import project_point
from vrusim.sim.observation import Observation

LEAD_SPEED_MPS = 0.5
"""Along-route speed above which a VRU in the corridor counts as a lead, m/s."""


@njit(cache=True, inline="always")
def update_track(t, detected, x, y, vx, vy, memory_s, track):  # pragma: no cover (compiled)
    """Refresh one track (array [seen_s, x, y, vx, vy]) and return (known, x, y, vx, vy) predicted to now."""
    if detected:
        track[0], track[1], track[2], track[3], track[4] = t, x, y, vx, vy
        return True, x, y, vx, vy
    age = t - track[0]
    if age > memory_s:
        return False, track[1], track[2], track[3], track[4]
    return True, track[1] + track[3] * age, track[2] + track[4] * age, track[3], track[4]


@njit(cache=True, inline="always")
def analyse_vru(
    xs,
    ys,
    tangents,
    kappas,
    counts,
    inv_spacing,
    width,
    offset,
    station_guess,
    front_station,
    half_width,
    radius,
    margin,
    horizon,
    x,
    y,
    vx,
    vy,
):  # pragma: no cover (compiled)
    """Conflict facts of one VRU: (station, conflict, lead, distance m, along speed m/s, t_in s, t_out s)."""
    station, px, py, tx, ty, _ = project_point(
        xs, ys, tangents, kappas, counts, inv_spacing, width, offset, station_guess, x, y, 2
    )
    lateral = tx * (y - py) - ty * (x - px)
    along = vx * tx + vy * ty
    cross = vy * tx - vx * ty
    half = half_width + radius + margin
    in_corridor = abs(lateral) <= half
    if abs(cross) > 1e-6:
        t1, t2 = (-half - lateral) / cross, (half - lateral) / cross
        t_in, t_out = min(t1, t2), max(t1, t2)
    elif in_corridor:
        t_in, t_out = -np.inf, np.inf
    else:
        t_in, t_out = np.inf, -np.inf
    lead_time = min(max(t_in, 0.0), horizon)
    entry = project_point(
        xs,
        ys,
        tangents,
        kappas,
        counts,
        inv_spacing,
        width,
        offset,
        station,
        x + vx * lead_time,
        y + vy * lead_time,
        2,
    )[0]
    distance = max(min(station, entry) - radius - front_station, 0.0)
    ahead = station + radius >= front_station
    conflict = ahead and t_out >= 0.0 and t_in <= horizon
    lead = conflict and in_corridor and along > LEAD_SPEED_MPS and along > abs(cross)
    return station, conflict, lead, distance, along, t_in, t_out


@dataclass
class Conflicts:
    """Per-VRU conflict facts, [B, K]."""

    conflict: np.ndarray
    lead: np.ndarray
    distance_m: np.ndarray
    along_speed_mps: np.ndarray
    enter_s: np.ndarray
    """When the VRU enters the corridor, s from now (-inf: already in)."""
    leave_s: np.ndarray
    """When it leaves the corridor, s from now (inf: never)."""


class ConflictTracker:
    """Batch conflict analysis with track memory, for planners written in NumPy."""

    def __init__(self, horizon_s: np.ndarray, margin_m: np.ndarray, memory_s: np.ndarray):
        self.horizon_s, self.margin_m, self.memory_s = horizon_s, margin_m, memory_s
        self.tracks: np.ndarray | None = None
        self.station: np.ndarray | None = None

    def analyse(self, obs: Observation) -> Conflicts:
        """Conflict facts for every VRU slot of every variant."""
        shape = obs.vru_x_m.shape
        if self.tracks is None:
            self.tracks = np.zeros((*shape, 5))
            self.tracks[..., 0] = -np.inf
            offsets = np.broadcast_to(obs.route_offset[:, None], shape)
            self.station = obs.routes.project_global(offsets // obs.routes.width, obs.vru_x_m, obs.vru_y_m) * 1.0
        out = np.empty((6, *shape))
        _analyse_batch(
            *obs.routes.arrays,
            obs.route_offset,
            obs.t_s,
            obs.ego_station_m + obs.rear_to_front_m,
            obs.half_width_m,
            obs.vru_radius_m,
            self.margin_m,
            self.horizon_s,
            self.memory_s,
            obs.detected,
            obs.vru_x_m,
            obs.vru_y_m,
            obs.vru_vx_mps,
            obs.vru_vy_mps,
            self.tracks,
            self.station,
            out,
        )
        return Conflicts(out[0] > 0.5, out[1] > 0.5, out[2], out[3], out[4], out[5])


@njit(cache=True)
def _analyse_batch(
    xs,
    ys,
    tangents,
    kappas,
    counts,
    inv_spacing,
    width,
    offsets,
    t,
    front_station,
    half_width,
    radius,
    margin,
    horizon,
    memory,
    detected,
    vx_x,
    vx_y,
    v_vx,
    v_vy,
    tracks,
    station,
    out,
):  # pragma: no cover
    B, K = vx_x.shape
    for b in range(B):
        for k in range(K):
            known, x, y, vx, vy = update_track(
                t, detected[b, k], vx_x[b, k], vx_y[b, k], v_vx[b, k], v_vy[b, k], memory[b], tracks[b, k]
            )
            s, conflict, lead, distance, along, t_in, t_out = analyse_vru(
                xs,
                ys,
                tangents,
                kappas,
                counts,
                inv_spacing,
                width,
                offsets[b],
                station[b, k],
                front_station[b],
                half_width[b],
                radius[b, k],
                margin[b],
                horizon[b],
                x,
                y,
                vx,
                vy,
            )
            if known:
                station[b, k] = s
            out[0, b, k] = 1.0 if (known and conflict) else 0.0
            out[1, b, k] = 1.0 if (known and lead) else 0.0
            out[2, b, k], out[3, b, k], out[4, b, k], out[5, b, k] = distance, along, t_in, t_out
