"""Loss model `distance`: delivery ratio 1 / (1 + exp((d - d50_m) / scale_m)) at RSU–ego distance d."""

from __future__ import annotations

import math

from vrusim.kernels import njit
from vrusim.scenario.v2x import DistanceLoss
from vrusim.sim.rng import STREAM_V2X_LOSS, uniform
from vrusim.sim.v2x.loss.registry import register_builtin

CODE = 3


def pack(spec: DistanceLoss) -> tuple[float, ...]:
    """(d50_m, scale_m)."""
    return (spec.d50_m, spec.scale_m)


@njit(cache=True, inline="always")
def lost(n, b, k, seed, params, link_state, link_distance):  # pragma: no cover (compiled)
    """Whether the message of VRU k generated at step n is lost at the variant's link distance."""
    z = min((link_distance - params[b, 0]) / params[b, 1], 700.0)
    return uniform(seed, n, STREAM_V2X_LOSS, k) >= 1.0 / (1.0 + math.exp(z))


register_builtin(DistanceLoss, pack, CODE)
