"""`VruVectorEnv`: N sub-environments stepped together on the batch engine, with next-step autoreset.

The engine advances a batch on one clock, so sub-environments whose episodes started at the same step share a
batch (a *cohort*, an `EpisodeBatch`); a sub-environment that ended is reset on the following `step()` call
(Gymnasium's `AutoresetMode.NEXT_STEP`: that call ignores its action and returns its first observation with
reward 0, terminated and truncated False) into a new cohort of every sub-environment reset at that call.
Sub-environments that run in lock-step (same start, same episode length) therefore stay in one batch; each
extra cohort costs one batch step per call. Results never depend on the cohort: a variant's run depends only on
its scenario (ARCHITECTURE principle 5), so sub-environment i reproduces a `VruEnv` given the same actions.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, ClassVar

import numpy as np
from gymnasium import spaces
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from vrusim.gym.env import checked_command
from vrusim.gym.episodes import EpisodeBatch
from vrusim.gym.features import DEFAULT_VRU_SLOTS, feature_names, observation_space
from vrusim.gym.reward import RewardWeights
from vrusim.gym.subset import take
from vrusim.scenario.schema import Scenario
from vrusim.sim.params import pack
from vrusim.sources import ScenarioSource, scenario_of


class _Cohort:
    """Sub-environments (`members`, env indices) whose episodes started at the same step, on one batch."""

    def __init__(self, episodes: EpisodeBatch, members: np.ndarray) -> None:
        self.episodes = episodes
        self.members = members
        self.live = np.ones(len(members), dtype=bool)
        """Member still runs its episode here (False once it ended or was reset elsewhere)."""


def _scenarios(scenario: ScenarioSource | Sequence[ScenarioSource], num_envs: int | None, v2x) -> list[Scenario]:
    sources = list(scenario) if isinstance(scenario, list | tuple) else [scenario]
    if num_envs is None:
        num_envs = len(sources)
    if len(sources) == 1:
        sources = sources * num_envs
    if len(sources) != num_envs or num_envs < 1:
        raise ValueError(f"num_envs={num_envs}: give one scenario or exactly num_envs scenarios ({len(sources)} given)")
    resolved: dict[int, Scenario] = {}  # the same source object is resolved once
    return [resolved.setdefault(id(s), scenario_of(s, v2x, argument="scenario")) for s in sources]


class VruVectorEnv(VectorEnv):
    """N VRU scenarios (N copies of one, or N different ones with the same `sim.dt_s`) as one vector env.

    Spaces per sub-environment as in `VruEnv`; the action space holds each sub-environment's own ego limits.
    """

    metadata: ClassVar[dict[str, Any]] = {"autoreset_mode": AutoresetMode.NEXT_STEP, "render_modes": []}

    def __init__(
        self,
        num_envs: int | None = None,
        scenario: ScenarioSource | Sequence[ScenarioSource] = "paper:pedestrian",
        v2x: bool | None = None,
        vru_slots: int = DEFAULT_VRU_SLOTS,
        reward_weights: RewardWeights | None = None,
        render_mode: str | None = None,
    ) -> None:
        if render_mode is not None:
            raise ValueError(
                f"render_mode: {render_mode!r} is not supported; expected None (the vector environment does not"
                " render; VruEnv takes 'human' or 'rgb_array')"
            )
        self.scenarios = _scenarios(scenario, num_envs, v2x)
        self.num_envs = len(self.scenarios)
        self.params = pack(self.scenarios)
        if self.params.vru_slots > vru_slots:
            raise ValueError(f"vru_slots={vru_slots}: a scenario has {self.params.vru_slots} VRUs")
        self.vru_slots = vru_slots
        self.reward_weights = reward_weights or RewardWeights()
        self.render_mode = render_mode
        self.feature_names = feature_names(vru_slots)
        self.single_observation_space = observation_space(vru_slots)
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self._low, self._high = -self.params.max_decel_mps2, self.params.max_accel_mps2
        self.single_action_space = spaces.Box(
            np.float32(self._low.min()), np.float32(self._high.max()), shape=(1,), dtype=np.float32
        )
        self.action_space = spaces.Box(
            self._low[:, None].astype(np.float32), self._high[:, None].astype(np.float32), dtype=np.float32
        )
        self._cohorts: list[_Cohort] = []
        self._autoreset = np.zeros(self.num_envs, dtype=bool)
        self._obs = np.zeros(self.observation_space.shape, dtype=np.float32)

    @property
    def cohorts(self) -> int:
        """Number of batches currently stepped per call (1 while every sub-environment runs in lock-step)."""
        return len(self._cohorts)

    def reset(
        self, *, seed: int | list[int] | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        """Reset every sub-environment (or those of `options["reset_mask"]`, bool [N]); observations [N, D]."""
        super().reset(seed=seed if isinstance(seed, int) or seed is None else seed[0])
        mask = np.ones(self.num_envs, dtype=bool)
        if options and "reset_mask" in options:
            mask = np.asarray(options["reset_mask"], dtype=bool).reshape(self.num_envs)
        envs = np.flatnonzero(mask)
        for cohort in self._cohorts:
            cohort.live &= ~mask[cohort.members]
        self._cohorts = [c for c in self._cohorts if c.live.any()]
        self._autoreset[envs] = False
        self._start(envs)
        return self._obs.copy(), {}

    def _start(self, envs: np.ndarray) -> None:
        params = self.params if len(envs) == self.num_envs else take(self.params, envs)
        cohort = _Cohort(EpisodeBatch(params, self.vru_slots, self.reward_weights), envs)
        self._obs[envs] = cohort.episodes.start()
        self._cohorts.append(cohort)

    def step(self, actions: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        """Advance every sub-environment one step (those that ended on the last call are reset instead)."""
        command = checked_command(actions, self._low, self._high)
        rewards = np.zeros(self.num_envs)
        terminated = np.zeros(self.num_envs, dtype=bool)
        truncated = np.zeros(self.num_envs, dtype=bool)
        infos: dict[str, Any] = {}
        for cohort in self._cohorts:
            positions = np.flatnonzero(cohort.live)
            envs = cohort.members[positions]
            batch_command = np.zeros(len(cohort.members))
            batch_command[positions] = command[envs]
            obs, reward, term, trunc = cohort.episodes.step(batch_command)
            self._obs[envs], rewards[envs] = obs[positions], reward[positions]
            terminated[envs], truncated[envs] = term[positions], trunc[positions]
            for position in positions[term[positions] | trunc[positions]]:
                cohort.live[position] = False
                infos = self._add_info(infos, {"metrics": cohort.episodes.summary(position)}, cohort.members[position])
        self._cohorts = [c for c in self._cohorts if c.live.any()]
        resets = np.flatnonzero(self._autoreset)
        if len(resets):
            self._start(resets)
        self._autoreset = terminated | truncated
        return self._obs.copy(), rewards, terminated, truncated, infos
