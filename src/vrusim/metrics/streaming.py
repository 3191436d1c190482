"""Streaming run metrics: reduced inside the step loop, so memory stays O(B), never O(B x steps)."""

from __future__ import annotations

import numpy as np

from vrusim.sim.batch import BatchParams


class RunMetrics:
    """Accumulates per-variant summaries step by step (see docs/metrics.md for each definition)."""

    def __init__(self, params: BatchParams, n_modes: int):
        B = params.size
        self.params = params
        inf = np.full(B, np.inf)
        nan = np.full(B, np.nan)
        self.collided = np.zeros(B, dtype=bool)
        self.contact_time_s = nan.copy()
        self.impact_ego_speed_mps = nan.copy()
        self.impact_relative_speed_mps = nan.copy()
        self.impact_relative_longitudinal_mps = nan.copy()
        self.impact_local_x_m = nan.copy()
        self.impact_local_y_m = nan.copy()
        self.impact_vru = np.full(B, -1)
        self.min_clearance_m = inf.copy()
        self.min_clearance_time_s = nan.copy()
        self.min_ttc_s = inf.copy()
        self.min_ttc_time_s = nan.copy()
        self.peak_accel_mps2 = np.zeros(B)
        self.peak_decel_mps2 = np.zeros(B)
        self.peak_jerk_mps3 = np.zeros(B)
        self.peak_lateral_accel_mps2 = np.zeros(B)
        self.sum_accel_sq = np.zeros(B)
        self.sum_jerk_sq = np.zeros(B)
        self.elapsed_s = np.zeros(B)
        self.travel_time_s = nan.copy()
        self.first_sensor_s = nan.copy()
        self.first_v2x_s = nan.copy()
        self.first_mode_s = np.full((B, n_modes), np.nan)
        self.transitions: list[tuple[float, int, int, int]] = []
        self.end_time_s = np.zeros(B)
        self.final_speed_mps = params.start_speed_mps.copy()
        self.final_station_m = np.zeros(B)
        self.prev_actuator = np.zeros(B)
        self.prev_clearance = np.full(B, np.inf)
        self.prev_speed = params.start_speed_mps.copy()

    def record_detection(self, t_s: float, active, sensed, v2x_received) -> None:
        """First times any VRU is perceived by the sensor / received over V2X."""
        sensed_any = sensed.any(axis=1) & active
        v2x_any = v2x_received.any(axis=1) & active
        self.first_sensor_s = np.where(sensed_any & np.isnan(self.first_sensor_s), t_s, self.first_sensor_s)
        self.first_v2x_s = np.where(v2x_any & np.isnan(self.first_v2x_s), t_s, self.first_v2x_s)

    def record_modes(self, t_s: float, active, old_mode, new_mode) -> None:
        """Every planner state transition, with its time."""
        changed = active & (old_mode != new_mode)
        if changed.any():
            for b in np.flatnonzero(changed):
                self.transitions.append((t_s, int(b), int(old_mode[b]), int(new_mode[b])))
                if np.isnan(self.first_mode_s[b, new_mode[b]]):
                    self.first_mode_s[b, new_mode[b]] = t_s

    def record_step(self, t_s: float, active, ego_speed, ego_accel, actuator, curvature, moving_before,
                    clearance, ttc, station, contact_info) -> None:
        """Fold one step (ending at t_s) into the summaries of the active variants."""
        dt = self.params.dt_s
        jerk = np.where(moving_before, (actuator - self.prev_actuator) * (1.0 / dt), 0.0)
        self.prev_actuator = actuator
        lateral = ego_speed * ego_speed * np.abs(curvature)
        on = active
        self.peak_accel_mps2 = np.where(on, np.maximum(self.peak_accel_mps2, ego_accel), self.peak_accel_mps2)
        self.peak_decel_mps2 = np.where(on, np.maximum(self.peak_decel_mps2, -ego_accel), self.peak_decel_mps2)
        self.peak_jerk_mps3 = np.where(on, np.maximum(self.peak_jerk_mps3, np.abs(jerk)), self.peak_jerk_mps3)
        self.peak_lateral_accel_mps2 = np.where(
            on, np.maximum(self.peak_lateral_accel_mps2, lateral), self.peak_lateral_accel_mps2
        )
        self.sum_accel_sq += np.where(on, ego_accel * ego_accel * dt, 0.0)
        self.sum_jerk_sq += np.where(on, jerk * jerk * dt, 0.0)
        self.elapsed_s += np.where(on, dt, 0.0)

        closest = clearance.min(axis=1)
        better = on & (closest < self.min_clearance_m)
        self.min_clearance_m = np.where(better, closest, self.min_clearance_m)
        self.min_clearance_time_s = np.where(better, t_s, self.min_clearance_time_s)
        soonest = ttc.min(axis=1)
        sooner = on & (soonest < self.min_ttc_s)
        self.min_ttc_s = np.where(sooner, soonest, self.min_ttc_s)
        self.min_ttc_time_s = np.where(sooner, t_s, self.min_ttc_time_s)

        arrived = on & np.isnan(self.travel_time_s) & (station >= self.params.route_length_m)
        self.travel_time_s = np.where(arrived, t_s, self.travel_time_s)

        new_contact = on & ~self.collided & (closest <= 0.0)
        if new_contact.any():
            self._record_contact(t_s, new_contact, closest, ego_speed, contact_info)
        self.prev_clearance = closest
        self.prev_speed = ego_speed
        self.end_time_s = np.where(on, t_s, self.end_time_s)
        self.final_speed_mps = np.where(on, ego_speed, self.final_speed_mps)
        self.final_station_m = np.where(on, station, self.final_station_m)

    def _record_contact(self, t_s, new_contact, closest, ego_speed, contact_info) -> None:
        """First contact: time and ego speed interpolated inside the step where clearance crossed zero."""
        dt = self.params.dt_s
        vru_index, rel_speed, rel_long, local_x, local_y = contact_info()
        before = self.prev_clearance
        with np.errstate(divide="ignore", invalid="ignore"):
            frac = np.where(np.isfinite(before) & (before > closest), before / (before - closest), 1.0)
        frac = np.clip(frac, 0.0, 1.0)
        t_contact = t_s - dt + frac * dt
        speed = self.prev_speed + frac * (ego_speed - self.prev_speed)
        self.collided |= new_contact
        self.contact_time_s = np.where(new_contact, t_contact, self.contact_time_s)
        self.impact_ego_speed_mps = np.where(new_contact, speed, self.impact_ego_speed_mps)
        self.impact_relative_speed_mps = np.where(new_contact, rel_speed, self.impact_relative_speed_mps)
        self.impact_relative_longitudinal_mps = np.where(
            new_contact, rel_long, self.impact_relative_longitudinal_mps
        )
        self.impact_local_x_m = np.where(new_contact, local_x, self.impact_local_x_m)
        self.impact_local_y_m = np.where(new_contact, local_y, self.impact_local_y_m)
        self.impact_vru = np.where(new_contact, vru_index, self.impact_vru)
