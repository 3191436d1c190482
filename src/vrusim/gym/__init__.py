"""Gymnasium environments on the vrusim engine; importing this package registers their ids.

    import gymnasium, vrusim.gym
    env = gymnasium.make("vrusim/PaperPedestrian-v0", v2x=True)
    envs = gymnasium.make_vec("vrusim/PaperPedestrian-v0", num_envs=1000, vectorization_mode="vector_entry_point")

Without importing it first: `gymnasium.make("vrusim.gym:vrusim/PaperPedestrian-v0")`. Spaces, reward and
autoreset: docs/interop.md (Gymnasium).
"""

from __future__ import annotations

from vrusim.extras import extra

with extra("gym"):  # every module of the package comes through here first
    from vrusim.gym.env import VruEnv
    from vrusim.gym.features import feature_names
    from vrusim.gym.registration import ENV_IDS, register_envs
    from vrusim.gym.reward import RewardWeights
    from vrusim.gym.vector_env import VruVectorEnv

register_envs()

__all__ = ["ENV_IDS", "RewardWeights", "VruEnv", "VruVectorEnv", "feature_names", "register_envs"]
