"""The planner interface: any object with `reset` and `act` can drive the ego.

A planner is created once, `reset(params)` is called before a batch starts (it may read per-variant parameters
from `params.scenarios[b].planner.params`), and `act(observation)` is called every step and returns the
commanded longitudinal acceleration per variant, m/s^2, shape [B]. Planners with discrete modes expose
`mode_names` (a tuple of names) and `mode` (int array [B], index into `mode_names`) so that the engine records
every transition with its time.
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np

from vrusim.sim.compaction import take_members
from vrusim.sim.observation import Observation
from vrusim.sim.params import BatchParams


@runtime_checkable
class Planner(Protocol):
    """Longitudinal motion planner for a batch of egos."""

    def reset(self, params: BatchParams) -> None:
        """Prepare for a new batch."""

    def act(self, observation: Observation) -> np.ndarray:
        """Commanded acceleration per variant, m/s^2."""


class HoldSpeedPlanner:
    """The `none` planner: commands zero acceleration, so the ego holds its start speed (protocol checks)."""

    mode_names = ("hold",)

    def reset(self, params: BatchParams) -> None:
        """Allocate the mode array."""
        self.mode = np.zeros(params.size, dtype=np.int8)

    def compact(self, index: np.ndarray) -> None:
        """Keep only variants `index` (the engine drops stopped ones)."""
        take_members(self, index)

    def act(self, observation: Observation) -> np.ndarray:
        """Zero acceleration for every variant."""
        return np.zeros(observation.ego_speed_mps.shape)
