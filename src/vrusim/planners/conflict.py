"""Conflict analysis of detected VRUs against the ego's own route (shared by rule-based planners).

Each VRU track is projected onto the ego route (Frenet frame: station s along the route, lateral offset e,
left positive) and its velocity and acceleration split into along-route and cross-route parts. Under constant
acceleration in that frame (a VRU setting off is predicted to keep speeding up; one at its top speed has none),
the VRU occupies the ego's corridor (|e| <= ego half width + VRU radius + margin) during a time window
[t_in, t_out]. A VRU *conflicts* with the ego path when it is tracked, not yet clear of the ego's swept
footprint (its far edge is still ahead of the ego's rear bumper along the route: a VRU beside the flank still
counts), and its corridor window overlaps [0, horizon]. The distance to it is measured along the route from
the front bumper to the VRU's near edge, at its current position or at its predicted corridor entry, whichever
is nearer (the entry point matters on curved routes), and is 0 for a VRU beside the ego. A conflicting VRU in
the corridor that moves along the route faster than `LEAD_SPEED_MPS` (and more along than across) is a *lead*
to follow rather than a crossing.

Track memory: a VRU that drops out of detection (for instance out of the sensor sector beside the bumper) is
still considered for `memory_s` seconds at its last detected position, predicted forward at its last detected
velocity.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from vrusim.geometry.path_table import nearest_station, project_from, project_point
from vrusim.kernels import njit
from vrusim.sim.observation import Observation

LEAD_SPEED_MPS = 0.5
"""Along-route speed above which a VRU in the corridor counts as a lead, m/s."""
TRACK_SIZE = 7
"""A track row: time last seen s, then x, y, vx, vy, ax, ay of the last estimate."""


@njit(cache=True, inline="always")
def update_track(t, detected, estimate, b, k, memory_s, track):  # pragma: no cover (compiled)
    """Refresh one track from `estimate[:, b, k]`; return (known, x, y, vx, vy, ax, ay) predicted to now.

    A lost track is predicted at constant velocity (its acceleration is no longer trusted) until it is older
    than `memory_s`. A never-seen track has seen time -inf.
    """
    if detected:
        track[0] = t
        for row in range(6):
            track[1 + row] = estimate[row, b, k]
        return True, track[1], track[2], track[3], track[4], track[5], track[6]
    age = t - track[0]
    if not age <= memory_s:
        return False, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    return True, track[1] + track[3] * age, track[2] + track[4] * age, track[3], track[4], 0.0, 0.0


@njit(cache=True, inline="always")
def warm_station(path, offset, was_known, x, y, station):  # pragma: no cover (compiled)
    """Start station for projecting a track: its previous projection, or a global search if it is new.

    A track is new when it was unknown before this step (never seen, or lost for longer than the memory):
    the VRU may have moved anywhere meanwhile, and a local Newton step could settle on the wrong branch of a
    curved route.
    """
    return station if was_known else nearest_station(path, offset, x, y)


@njit(cache=True, inline="always")
def _positive_roots(a, b, c):  # pragma: no cover (compiled)
    """The positive roots of a t^2 + b t + c = 0 (a may be 0), smaller first; inf where there is none."""
    lo = hi = np.inf
    if a == 0.0:
        if b != 0.0 and -c / b > 0.0:
            lo = -c / b
        return lo, hi
    disc = b * b - 4.0 * a * c
    if disc < 0.0:
        return lo, hi
    root = math.sqrt(disc)
    r1, r2 = (-b - root) / (2.0 * a), (-b + root) / (2.0 * a)
    r1, r2 = min(r1, r2), max(r1, r2)
    if r1 > 0.0:
        lo, hi = r1, r2
    elif r2 > 0.0:
        lo = r2
    return lo, hi


@njit(cache=True, inline="always")
def corridor_window(lateral, cross_speed, cross_accel, half):  # pragma: no cover (compiled)
    """First time window (s from now) in which |e(t)| <= half, e(t) = lateral + cross_speed t + cross_accel t^2/2.

    Returns (t_in, t_out): t_in = -inf when inside now; (inf, -inf) when never inside. The window's ends are
    the first two boundary crossings after now (allocation-free merge of the roots of e(t) = +-half).
    """
    a1, b1 = _positive_roots(0.5 * cross_accel, cross_speed, lateral - half)
    a2, b2 = _positive_roots(0.5 * cross_accel, cross_speed, lateral + half)
    first = min(a1, a2)
    second = min(max(a1, a2), b1, b2)
    if abs(lateral) <= half:
        return -np.inf, first
    if first == np.inf:
        return np.inf, -np.inf
    return first, second


@njit(cache=True, inline="always")
def analyse_vru(
    path,
    offset,
    station_guess,
    front_station,
    rear_station,
    half_width,
    radius,
    margin,
    horizon,
    x,
    y,
    vx,
    vy,
    ax,
    ay,
    every_distance,
):  # pragma: no cover (compiled)
    """Conflict facts of one VRU: (station, conflict, lead, distance m, along speed m/s, t_in s, t_out s).

    `front_station` and `rear_station` are the route stations of the ego's front and rear bumpers, m: the VRU
    is tracked until its far edge is behind the rear bumper (clear of the swept footprint). The distance of a
    VRU that does not conflict is inf unless `every_distance` (the built-in planners read it for conflicts
    only, which spares them the entry projection).
    """
    station, px, py, tx, ty, kappa = project_point(path, offset, station_guess, x, y, 2)
    lateral = tx * (y - py) - ty * (x - px)
    along = vx * tx + vy * ty
    cross = vy * tx - vx * ty
    half = half_width + radius + margin
    in_corridor = abs(lateral) <= half
    t_in, t_out = corridor_window(lateral, cross, ay * tx - ax * ty, half)
    ahead = station + radius >= rear_station
    conflict = ahead and t_out >= 0.0 and t_in <= horizon
    distance = np.inf
    if conflict or every_distance:
        lead_time = min(max(t_in, 0.0), horizon)
        # Newton from `station`, where the projection above ended: its last evaluation is reused
        entry = project_from(
            path,
            offset,
            station,
            px,
            py,
            tx,
            ty,
            kappa,
            x + (vx + 0.5 * ax * lead_time) * lead_time,
            y + (vy + 0.5 * ay * lead_time) * lead_time,
            2,
        )[0]
        distance = max(min(station, entry) - radius - front_station, 0.0)
    lead = conflict and in_corridor and along > LEAD_SPEED_MPS and along > abs(cross)
    return station, conflict, lead, distance, along, t_in, t_out


@njit(cache=True, inline="always")
def track_and_analyse(
    path,
    offset,
    t,
    detected,
    estimate,
    b,
    k,
    memory_s,
    track,
    station,
    front_station,
    rear_station,
    half_width,
    radius,
    margin,
    horizon,
    every_distance,
):  # pragma: no cover (compiled)
    """One VRU slot for one step: refresh its track, then its conflict facts (see `analyse_vru`).

    Returns (known, station, conflict, lead, distance m, along speed m/s, t_in s, t_out s); when the track is
    unknown the rest is meaningless and `station` is returned unchanged.
    """
    was_known = t - track[0] <= memory_s
    known, x, y, vx, vy, ax, ay = update_track(t, detected, estimate, b, k, memory_s, track)
    if not known:
        return False, station, False, False, np.inf, 0.0, np.inf, -np.inf
    guess = warm_station(path, offset, was_known, x, y, station)
    s, conflict, lead, distance, along, t_in, t_out = analyse_vru(
        path, offset, guess, front_station, rear_station, half_width, radius, margin, horizon, x, y, vx, vy, ax, ay,
        every_distance,
    )  # fmt: skip
    return True, s, conflict, lead, distance, along, t_in, t_out


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
            self.tracks, self.station = new_tracks(obs)
        out = np.empty((6, *shape))
        _analyse_batch(
            obs.routes.arrays,
            obs.route_offset,
            obs.t_s,
            obs.ego_station_m + obs.rear_to_front_m,
            obs.ego_length_m,
            obs.half_width_m,
            obs.vru_radius_m,
            self.margin_m,
            self.horizon_s,
            self.memory_s,
            obs.detected,
            obs.vru_estimate,
            self.tracks,
            self.station,
            out,
        )
        return Conflicts(out[0] > 0.5, out[1] > 0.5, out[2], out[3], out[4], out[5])


def new_tracks(obs: Observation) -> tuple[np.ndarray, np.ndarray]:
    """Empty tracks [B, K, TRACK_SIZE] and their route stations (set when a track is first acquired)."""
    shape = obs.vru_x_m.shape
    tracks = np.zeros((*shape, TRACK_SIZE))
    tracks[..., 0] = -np.inf
    return tracks, np.zeros(shape)


@njit(cache=True)
def _analyse_batch(
    path,
    offsets,
    t,
    front_station,
    ego_length,
    half_width,
    radius,
    margin,
    horizon,
    memory,
    detected,
    estimate,
    tracks,
    station,
    out,
):  # pragma: no cover
    B, K = detected.shape
    for b in range(B):
        for k in range(K):
            _, station[b, k], conflict, lead, distance, along, t_in, t_out = track_and_analyse(
                path,
                offsets[b],
                t,
                detected[b, k],
                estimate,
                b,
                k,
                memory[b],
                tracks[b, k],
                station[b, k],
                front_station[b],
                front_station[b] - ego_length[b],  # tracked until clear of the rear bumper
                half_width[b],
                radius[b, k],
                margin[b],
                horizon[b],
                True,  # `Conflicts` reports every VRU's distance
            )
            out[0, b, k] = 1.0 if conflict else 0.0
            out[1, b, k] = 1.0 if lead else 0.0
            out[2, b, k], out[3, b, k], out[4, b, k], out[5, b, k] = distance, along, t_in, t_out
