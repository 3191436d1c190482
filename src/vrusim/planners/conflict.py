"""Conflict analysis of detected VRUs against the ego's own route (shared by rule-based planners).

Each detected VRU is projected onto the ego route (Frenet frame: station s along the route, lateral offset e,
left positive) and its velocity split into along-route and cross-route parts. Under constant velocity in
that frame, the VRU occupies the ego's corridor (|e| <= ego half width + VRU radius + margin) during a time
window [t_in, t_out]. A VRU *conflicts* with the ego path when it is detected, ahead of the ego's front bumper,
and its corridor window overlaps [0, horizon]. The distance to it is measured along the route from the front
bumper to the VRU's near edge, at its current position or at its predicted corridor entry, whichever is
nearer (the entry point matters on curved routes). A conflicting VRU in the corridor that moves along the route faster than
`lead_speed_mps` (and more along than across) is a *lead* to follow rather than a crossing.

Track memory: a VRU that drops out of detection (for instance out of the sensor sector beside the bumper) is
still considered for `memory_s` seconds at its last detected position, predicted forward at its last detected
velocity.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vrusim.sim.observation import Observation


@dataclass
class Conflicts:
    """Per-VRU conflict facts, [B, K]."""

    conflict: np.ndarray
    lead: np.ndarray
    distance_m: np.ndarray
    along_speed_mps: np.ndarray
    in_corridor: np.ndarray


class ConflictTracker:
    """Keeps each VRU's warm-started projection onto the ego route between steps."""

    def __init__(self, horizon_s: np.ndarray, margin_m: np.ndarray, memory_s: np.ndarray,
                 lead_speed_mps: float = 0.5):
        self.horizon_s = horizon_s[:, None]
        self.margin_m = margin_m[:, None]
        self.memory_s = memory_s[:, None]
        self.lead_speed_mps = lead_speed_mps
        self.station: np.ndarray | None = None

    def _remember(self, obs: Observation):
        """Fresh detections replace the tracks; lost ones are predicted forward until they are too old."""
        if self.station is None:
            shape = obs.vru_x_m.shape
            self.seen_s = np.full(shape, -np.inf)
            self.track = [np.zeros(shape) for _ in range(4)]
            offset = np.broadcast_to(obs.route_offset[:, None], shape)
            self.station = obs.routes.project_global(offset // obs.routes.width, obs.vru_x_m, obs.vru_y_m) * 1.0
        fresh = obs.detected
        self.seen_s = np.where(fresh, obs.t_s, self.seen_s)
        for index, value in enumerate((obs.vru_x_m, obs.vru_y_m, obs.vru_vx_mps, obs.vru_vy_mps)):
            self.track[index] = np.where(fresh, value, self.track[index])
        age = obs.t_s - self.seen_s
        known = age <= self.memory_s
        x, y, vx, vy = self.track
        lost_age = np.where(fresh, 0.0, np.minimum(age, self.memory_s))
        return known, x + vx * lost_age, y + vy * lost_age, vx, vy

    def analyse(self, obs: Observation) -> Conflicts:
        """Conflict facts for every VRU slot of every variant."""
        known, vru_x, vru_y, vru_vx, vru_vy = self._remember(obs)
        offset = np.broadcast_to(obs.route_offset[:, None], vru_x.shape)
        station, px, py, tx, ty, _ = obs.routes.project(offset, self.station, vru_x, vru_y)
        self.station = np.where(known, station, self.station)
        lateral = tx * (vru_y - py) - ty * (vru_x - px)
        along_speed = vru_vx * tx + vru_vy * ty
        cross_speed = vru_vy * tx - vru_vx * ty
        half = obs.half_width_m[:, None] + obs.vru_radius_m + self.margin_m
        in_corridor = np.abs(lateral) <= half
        moving = np.abs(cross_speed) > 1e-6
        with np.errstate(divide="ignore", invalid="ignore"):
            t1 = np.where(moving, (-half - lateral) / cross_speed, 0.0)
            t2 = np.where(moving, (half - lateral) / cross_speed, 0.0)
        t_in = np.where(moving, np.minimum(t1, t2), np.where(in_corridor, -np.inf, np.inf))
        t_out = np.where(moving, np.maximum(t1, t2), np.where(in_corridor, np.inf, -np.inf))
        # where a crossing VRU will enter the corridor: project its predicted entry position onto the route
        lead_time = np.clip(t_in, 0.0, self.horizon_s)
        entry_station, *_ = obs.routes.project(offset, station, vru_x + vru_vx * lead_time, vru_y + vru_vy * lead_time)
        front_station = (obs.ego_station_m + obs.rear_to_front_m)[:, None]
        distance = np.minimum(station, entry_station) - obs.vru_radius_m - front_station
        ahead = station + obs.vru_radius_m >= front_station
        conflict = known & ahead & (t_out >= 0.0) & (t_in <= self.horizon_s)
        lead = conflict & in_corridor & (along_speed > self.lead_speed_mps) & (along_speed > np.abs(cross_speed))
        return Conflicts(conflict, lead, np.maximum(distance, 0.0), along_speed, in_corridor)
