"""A test plug-in planner: holds speed and raises its forward-collision warning while any VRU is detected."""

from __future__ import annotations

import numpy as np

from vrusim.planners.base import HoldSpeedPlanner


class WarnOnDetection(HoldSpeedPlanner):
    """Warns from the first detection of any VRU on; never brakes."""

    def reset(self, params) -> None:
        super().reset(params)
        self.warning = np.zeros(params.size, dtype=bool)

    def act(self, observation):
        self.warning = self.warning | observation.detected.any(axis=1)
        return super().act(observation)
