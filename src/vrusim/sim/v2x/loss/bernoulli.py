"""Loss model `bernoulli`: each message is lost independently with `probability` (params[0])."""

from __future__ import annotations

from vrusim.kernels import njit
from vrusim.scenario.v2x import BernoulliLoss
from vrusim.sim.rng import STREAM_V2X_LOSS, uniform
from vrusim.sim.v2x.loss.registry import register_builtin

CODE = 1


def pack(spec: BernoulliLoss) -> tuple[float, ...]:
    """(probability,)."""
    return (spec.probability,)


@njit(cache=True, inline="always")
def lost(n, b, k, seed, params, link_state, link_distance):  # pragma: no cover (compiled)
    """Whether the message of VRU k generated at step n is lost."""
    return uniform(seed, n, STREAM_V2X_LOSS, k) < params[b, 0]


register_builtin(BernoulliLoss, pack, CODE)
