"""B episodes started together on one `EpisodeStepper`: observation vectors, rewards, done flags, end summaries."""

from __future__ import annotations

from typing import Any

import numpy as np

from vrusim.gym.features import observation_vectors
from vrusim.gym.reward import RewardModel, RewardWeights
from vrusim.gym.stepper import EpisodeStepper
from vrusim.metrics.catalog import BatchView, is_builtin, metrics
from vrusim.metrics.columns import columns_of
from vrusim.sim.observation import Observation
from vrusim.sim.params import BatchParams


def summary_columns() -> tuple[str, ...]:
    """Result columns reported in `info["metrics"]` when an episode ends: `collided`, `outcome` (collision, avoided,
    stalled or incomplete), the float measures, every
    bool or numeric measure a plug-in registered (`vrusim.register_metric`), then the scores. A per-VRU measure
    (`min_ttc_per_vru_s`) adds its columns per VRU slot (`min_ttc_vru<k>_s`) besides these."""
    measures = [
        m.name
        for m in metrics()
        if m.group == "measure"
        and m.split is None
        and (m.dtype == "float64" or (m.dtype != "string" and not is_builtin(m.name)))
    ]
    return ("collided", "outcome", *measures, *(m.name for m in metrics() if m.group == "score"))


SUMMARY_COLUMNS = summary_columns()
"""The built-in columns of `summary_columns` (plug-in metrics add theirs once registered)."""


class EpisodeBatch:
    """Episodes of every variant of `params`, in lock-step from time 0."""

    def __init__(self, params: BatchParams, vru_slots: int, weights: RewardWeights) -> None:
        self.params = params
        self.vru_slots = vru_slots
        self.stepper = EpisodeStepper(params)
        self.reward_model = RewardModel(params, weights)
        self.planner_observation: Observation | None = None
        self.columns: dict[str, np.ndarray] | None = None
        self.vru_columns: tuple[str, ...] = ()
        """The per-VRU measures' columns (`min_ttc_vru0_s`, ...), known once `columns` are."""

    def start(self) -> np.ndarray:
        """Restart every episode; the first observation vectors [B, D]."""
        self.stepper.reset()
        self.columns = None
        return self._observe()

    def _observe(self) -> np.ndarray:
        self.planner_observation = self.stepper.observe()
        return observation_vectors(self.params, self.planner_observation, self.vru_slots)

    def step(self, command: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Advance under `command` (m/s^2 [B]): (next observations, rewards, terminated, truncated), each [B]."""
        outcome = self.stepper.advance(command)
        ended = outcome.terminated | outcome.truncated
        scores = None
        if ended.any():
            view = BatchView(self.stepper.run())
            self.columns = columns_of(view)
            self.vru_columns = tuple(
                name
                for m in metrics()
                if m.group == "measure" and m.split is not None
                for name in m.split(view, view[m.name])
            )
            scores = (self.columns["safety"] + self.columns["efficiency"] + self.columns["comfort"]) / 3.0
        reward = self.reward_model.step(outcome, scores)
        return self._observe(), reward, outcome.terminated, outcome.truncated

    def summary(self, b: int) -> dict[str, Any]:
        """Result columns of variant b after its episode ended (floats, NaN: absent; `collided` a bool, `outcome` a
        string)."""
        assert self.columns is not None
        return {name: _scalar(self.columns[name][b]) for name in (*summary_columns(), *self.vru_columns)}


def _scalar(value: Any) -> Any:
    if isinstance(value, str):
        return value
    return bool(value) if isinstance(value, np.bool_ | bool) else float(value)
