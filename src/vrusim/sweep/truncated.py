"""Draws of a truncated normal N(mean, std²) restricted to [low, high] for a sweep design.

Rejection sampling (draw normals, keep those inside, redraw the rest) is exact and what every earlier version
did, so its draws stay the design of a spec that worked before. It needs about ln(N) / mass rounds, though: for
a narrow window far in a tail it would run for minutes and still give up. When rejection is bound to give up
(it finishes within `MAX_REJECTION_ROUNDS` with probability below `HOPELESS`, or it did give up) the values are
drawn by the inverse CDF instead, also exactly: Φ⁻¹(Φ(a) + u (Φ(b) − Φ(a))), computed in the lower tail (a
window above the mean is mirrored) where Φ keeps its relative accuracy.
"""

from __future__ import annotations

import math

import numpy as np

from vrusim.sweep.normal import normal_cdf, normal_quantile
from vrusim.sweep.spec import Parameter, truncated_mass

MAX_REJECTION_ROUNDS = 100_000
"""Rounds of rejection sampling before it gives up (and the inverse CDF draws the values)."""
HOPELESS = 1e-12
"""Below this probability of finishing within `MAX_REJECTION_ROUNDS`, rejection is not tried."""


def truncated_mass_of(p: Parameter) -> float:
    """The probability N(mean, std²) gives [low, high] (as the spec check computes it)."""
    return truncated_mass(p.mean, p.std, p.low, p.high)


def rejection_finishes(mass: float, count: int, rounds: int = MAX_REJECTION_ROUNDS) -> float:
    """Probability that rejection accepts all `count` draws within `rounds` rounds: (1 − (1 − mass)^rounds)^count."""
    left = math.exp(rounds * math.log1p(-mass)) if mass < 1 else 0.0
    return math.exp(count * math.log1p(-left)) if left < 1 else 0.0


def _rejection(rng: np.random.Generator, p: Parameter, count: int) -> np.ndarray | None:
    """The draws by rejection, or None when it gave up."""
    out = np.empty(count)
    missing = np.arange(count)
    for _ in range(MAX_REJECTION_ROUNDS):
        draws = rng.normal(p.mean, p.std, missing.size)
        keep = (draws >= p.low) & (draws <= p.high)
        out[missing[keep]] = draws[keep]
        missing = missing[~keep]
        if missing.size == 0:
            return out
    return None


def _inverse_cdf(rng: np.random.Generator, p: Parameter, count: int) -> np.ndarray:
    a, b = (p.low - p.mean) / p.std, (p.high - p.mean) / p.std
    mirrored = a > 0  # computed in the lower tail
    if mirrored:
        a, b = -b, -a
    low, high = normal_cdf(a), normal_cdf(b)
    z = normal_quantile(low + rng.random(count) * (high - low))
    return np.clip(p.mean + p.std * (-z if mirrored else z), p.low, p.high)


def truncated_normal(rng: np.random.Generator, p: Parameter, count: int) -> np.ndarray:
    """`count` draws of the truncated normal `p` from `rng`: by rejection unless that is bound to give up."""
    if rejection_finishes(truncated_mass_of(p), count) >= HOPELESS:
        drawn = _rejection(rng, p, count)
        if drawn is not None:
            return drawn
    return _inverse_cdf(rng, p, count)
