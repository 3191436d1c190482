"""Brake at a constant deceleration as soon as a VRU is detected ahead of the front bumper."""

import numpy as np

from vrusim.planners.base import PlannerBase


class BrakeOnDetection(PlannerBase):  # optional base: declares mode_names, mode, warning with defaults
    mode_names = ("cruise", "braking")  # optional: lets vrusim record transitions

    def reset(self, params):
        # per-variant parameters from YAML `planner.params`; validate them yourself
        self.decel = np.array([float(given.get("decel_mps2", 4.0)) for given in params.planner_params])
        self.mode = np.zeros(params.size, dtype=np.int8)

    def act(self, obs):
        hx, hy = obs.ego_heading_x[:, None], obs.ego_heading_y[:, None]
        front_x = obs.ego_x_m[:, None] + obs.rear_to_front_m[:, None] * hx
        front_y = obs.ego_y_m[:, None] + obs.rear_to_front_m[:, None] * hy
        ahead = (obs.vru_x_m - front_x) * hx + (obs.vru_y_m - front_y) * hy > 0.0  # [B, K]
        seen = (obs.detected & ahead).any(axis=1)  # [B]
        self.mode = np.where(seen | (self.mode == 1), 1, 0).astype(np.int8)  # latch once seen
        hold = np.clip(0.8 * (obs.cruise_speed_mps - obs.ego_speed_mps), -2.0, 1.5)
        return np.where(self.mode == 1, -self.decel, hold)  # m/s^2, shape [B]
