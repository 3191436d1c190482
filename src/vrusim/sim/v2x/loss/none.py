"""Loss model `none`: every message sent within range arrives."""

from __future__ import annotations

from vrusim.scenario.v2x import NoLoss
from vrusim.sim.v2x.loss.registry import register_builtin

CODE = 0


def pack(spec: NoLoss) -> tuple[float, ...]:
    """No parameters."""
    return ()


register_builtin(NoLoss, pack, CODE)
