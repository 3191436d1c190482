"""Loss model `gilbert_elliott`: a two-state Markov link, one transition per message (docs/models.md, V2X).

params: (p_good_to_bad, p_bad_to_good, loss_good, loss_bad); the link state [B] is -1 before the first message
(then drawn from the stationary distribution), 0 good, 1 bad.
"""

from __future__ import annotations

from vrusim.kernels import njit
from vrusim.scenario.v2x import GilbertElliottLoss
from vrusim.sim.rng import STREAM_V2X_LOSS, STREAM_V2X_STATE, uniform
from vrusim.sim.v2x.loss.registry import register_builtin

CODE = 2


def pack(spec: GilbertElliottLoss) -> tuple[float, ...]:
    """(p_good_to_bad, p_bad_to_good, loss_good, loss_bad)."""
    return (spec.p_good_to_bad, spec.p_bad_to_good, spec.loss_good, spec.loss_bad)


@njit(cache=True, inline="always")
def lost(n, b, k, seed, params, link_state, link_distance):  # pragma: no cover (compiled)
    """Advance variant b's link state, then whether the message of VRU k generated at step n is lost."""
    p_gb, p_bg = params[b, 0], params[b, 1]
    u = uniform(seed, n, STREAM_V2X_STATE, k)
    state = link_state[b]
    if state < 0:  # first message: the stationary distribution
        state = 1 if u < p_gb / (p_gb + p_bg) else 0
    elif state == 0:
        state = 1 if u < p_gb else 0
    else:
        state = 0 if u < p_bg else 1
    link_state[b] = state
    loss = params[b, 3] if state == 1 else params[b, 2]
    return uniform(seed, n, STREAM_V2X_LOSS, k) < loss


register_builtin(GilbertElliottLoss, pack, CODE)
