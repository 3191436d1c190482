"""`VruEnv`: one scenario as a Gymnasium environment; the agent commands the ego's longitudinal acceleration."""

from __future__ import annotations

from typing import Any, ClassVar

import gymnasium
import numpy as np
from gymnasium import spaces
from matplotlib.figure import Figure

from vrusim.engine.stepper import BatchStepper
from vrusim.gym.episodes import EpisodeBatch
from vrusim.gym.features import DEFAULT_VRU_SLOTS, feature_names, observation_space
from vrusim.gym.render import EpisodeFrames, HumanWindow
from vrusim.gym.reward import RewardWeights
from vrusim.scenario.schema import Scenario
from vrusim.sim.observation import Observation
from vrusim.sim.params import pack
from vrusim.sources import ScenarioSource, scenario_of


def action_space(scenario: Scenario) -> spaces.Box:
    """Commanded acceleration, m/s^2, in [-max_decel, max_accel] of the scenario's ego (shape (1,))."""
    low, high = -scenario.ego.max_decel_mps2, scenario.ego.max_accel_mps2
    return spaces.Box(np.float32(low), np.float32(high), shape=(1,), dtype=np.float32)


def checked_command(action: Any, low: np.ndarray, high: np.ndarray) -> np.ndarray:
    """Actions [B] or [B, 1] as float64 m/s^2, clipped to the ego limits (as the ego dynamics clip a command)."""
    command = np.asarray(action, dtype=float).reshape(low.shape)
    if not np.isfinite(command).all():
        raise ValueError(f"action: expected finite accelerations in m/s^2, got {action!r}")
    return np.minimum(np.maximum(command, low), high)


class VruEnv(gymnasium.Env):
    """One VRU scenario, stepped at its `sim.dt_s`; observation, reward and spaces: docs/interop.md.

    An episode ends `terminated` at the first contact (if `sim.stop_on_collision`) or at the route end (if
    `sim.stop_at_route_end`), `truncated` at `sim.duration_s`. The final `info["metrics"]` holds the run's
    result columns (contact time, impact speed, min clearance / TTC, scores, ...). The episode is deterministic:
    the scenario's `sim.seed` keys its sensor and V2X randomness; `reset(seed=...)` only seeds `np_random`.
    """

    metadata: ClassVar[dict[str, Any]] = {"render_modes": ["human", "rgb_array"], "render_fps": 100}
    """`render_fps`: frames per second of wall-clock time, one frame per step, so 1 / `sim.dt_s` plays the episode
    in real time (each instance sets its own; 100 here is the default `sim.dt_s` of 0.01 s)."""

    def __init__(
        self,
        scenario: ScenarioSource,
        v2x: bool | None = None,
        vru_slots: int = DEFAULT_VRU_SLOTS,
        reward_weights: RewardWeights | None = None,
        render_mode: str | None = None,
    ) -> None:
        if render_mode not in (None, *self.metadata["render_modes"]):
            accepted = ", ".join(repr(mode) for mode in (None, *self.metadata["render_modes"]))
            raise ValueError(f"render_mode: {render_mode!r} is not supported; expected one of {accepted}")
        self.scenario = scenario_of(scenario, v2x, argument="scenario")
        self.metadata = {**type(self).metadata, "render_fps": 1.0 / self.scenario.sim.dt_s}  # one frame a step
        if len(self.scenario.vrus) > vru_slots:
            raise ValueError(f"vru_slots={vru_slots}: the scenario has {len(self.scenario.vrus)} VRUs")
        self.params = pack([self.scenario])
        self.vru_slots = vru_slots
        self.feature_names = feature_names(vru_slots)
        self.observation_space = observation_space(vru_slots)
        self.action_space = action_space(self.scenario)
        self.render_mode = render_mode
        self._low, self._high = -self.params.max_decel_mps2, self.params.max_accel_mps2
        self._episodes = EpisodeBatch(self.params, vru_slots, reward_weights or RewardWeights())
        self._running = False
        self._frames = EpisodeFrames(self.scenario) if render_mode is not None else None
        self._window = HumanWindow(self._frames, self.metadata["render_fps"]) if render_mode == "human" else None

    @property
    def planner_observation(self) -> Observation | None:
        """The current observation as a planner sees it (`vrusim.sim.observation.Observation`, batch of one)."""
        return self._episodes.planner_observation

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None) -> tuple[np.ndarray, dict]:
        """Back to time 0; the first observation."""
        super().reset(seed=seed)
        self._running = True
        observation = self._episodes.start()[0]
        if self._frames is not None:
            self._frames.restart(self._engine)
        if self._window is not None:
            self._window.show(self._episodes.stepper.run(), new_episode=True)
        return observation, {"t_s": 0.0}

    def step(self, action: Any) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        """Advance one step under the commanded acceleration (m/s^2, clipped to the ego limits)."""
        if not self._running:
            raise RuntimeError("VruEnv.step: the episode has ended (or not started); call reset()")
        command = checked_command(action, self._low, self._high)
        obs, reward, terminated, truncated = self._episodes.step(command)
        if self._frames is not None:
            self._frames.add(self._engine, command)
        if self._window is not None:
            self._window.show(self._episodes.stepper.run())
        done_terminated, done_truncated = bool(terminated[0]), bool(truncated[0])
        info: dict[str, Any] = {"t_s": self._episodes.stepper.t_s}
        if done_terminated or done_truncated:
            self._running = False
            info["metrics"] = self._episodes.summary(0)
        return obs[0], float(reward[0]), done_terminated, done_truncated, info

    @property
    def _engine(self) -> BatchStepper:
        """The engine step of the current episode."""
        return self._episodes.stepper.stepper

    @property
    def figure(self) -> Figure | None:
        """The matplotlib figure the scene is drawn on (None before the first frame; in human mode also after the
        window was closed)."""
        if self._window is not None:
            return self._window.figure
        return None if self._frames is None or self._frames.panel is None else self._frames.panel.figure

    def render(self) -> np.ndarray | None:
        """rgb_array: the current state as an RGB image (uint8 [H, W, 3]). human: None (`reset()` and `step()`
        already drew the window, as Gymnasium specifies). No render_mode: None."""
        if self._frames is None:
            return None
        if not self._frames.started:
            raise RuntimeError("VruEnv.render: call reset() first")
        if self._window is not None:
            return None
        return self._frames.frame(self._episodes.stepper.run())

    def close(self) -> None:
        """Close the human-mode window; release the rgb_array figure."""
        if self._window is not None:
            self._window.close()
        elif self._frames is not None:
            self._frames.forget_figure()
        super().close()
