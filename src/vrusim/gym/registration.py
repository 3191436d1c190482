"""Environment ids: one per paper case study (kwarg `v2x`, default off) and one for any scenario."""

from __future__ import annotations

import gymnasium

ENTRY_POINT = "vrusim.gym.env:VruEnv"
VECTOR_ENTRY_POINT = "vrusim.gym.vector_env:VruVectorEnv"

ENV_IDS: dict[str, dict] = {
    "vrusim/PaperPedestrian-v0": {"scenario": "paper:pedestrian", "v2x": False},
    "vrusim/PaperEscooter-v0": {"scenario": "paper:escooter", "v2x": False},
    "vrusim/PaperMotorcyclist-v0": {"scenario": "paper:motorcyclist", "v2x": False},
    "vrusim/Scenario-v0": {},
}
"""Id → default kwargs. `vrusim/Scenario-v0` needs `scenario=` (YAML path, catalogue test id, `paper:<case>` or
a Scenario)."""


def register_envs() -> None:
    """Register every id with Gymnasium (once; later calls change nothing)."""
    for env_id, kwargs in ENV_IDS.items():
        if env_id not in gymnasium.registry:
            gymnasium.register(
                env_id, entry_point=ENTRY_POINT, vector_entry_point=VECTOR_ENTRY_POINT, kwargs=dict(kwargs)
            )
