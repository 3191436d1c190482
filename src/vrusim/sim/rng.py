"""Counter-based random numbers: a draw depends only on (seed, step, stream, slot), never on the batch.

A variant's randomness is keyed by its scenario's `sim.seed`, the step index, a stream id (one per random
process: sensor detection, sensor noise, V2X loss, jitter, ...) and a slot (VRU index, or a component). The
same key always gives the same number, whichever batch, chunk, worker or machine runs the variant
(ARCHITECTURE principle 5). The generator is SplitMix64's finaliser applied to a combined 64-bit key
(Steele, Lea & Flood 2014, "Fast splittable pseudorandom number generators"), which passes BigCrush on
counter inputs; uniform doubles take its top 53 bits, normals use the Box–Muller transform.
"""

from __future__ import annotations

import math

import numpy as np
from numba import uint64

from vrusim.kernels import njit

_GOLDEN = uint64(0x9E3779B97F4A7C15)
_MIX1 = uint64(0xBF58476D1CE4E5B9)
_MIX2 = uint64(0x94D049BB133111EB)

STREAM_SENSOR_DETECT = 1
STREAM_SENSOR_NOISE = 2
STREAM_V2X_LOSS = 3
STREAM_V2X_JITTER = 4
STREAM_V2X_STATE = 5
STREAM_RSU_NOISE = 6
"""Stream ids: one per random process, so adding a process never shifts the numbers of another."""


@njit(cache=True, inline="always")
def _mix(z):  # pragma: no cover (compiled)
    z = (z ^ (z >> uint64(30))) * _MIX1
    z = (z ^ (z >> uint64(27))) * _MIX2
    return z ^ (z >> uint64(31))


@njit(cache=True, inline="always")
def hash_key(seed, step, stream, slot):  # pragma: no cover (compiled)
    """A well-mixed 64-bit value for the key (all four non-negative integers)."""
    z = _mix(uint64(seed) * _GOLDEN + uint64(stream))
    z = _mix(z + uint64(step) * _GOLDEN)
    return _mix(z + uint64(slot) * _GOLDEN + _GOLDEN)


@njit(cache=True, inline="always")
def uniform(seed, step, stream, slot):  # pragma: no cover (compiled)
    """A uniform double in [0, 1) for the key."""
    return float(hash_key(seed, step, stream, slot) >> uint64(11)) * (1.0 / 9007199254740992.0)


@njit(cache=True, inline="always")
def normal(seed, step, stream, slot):  # pragma: no cover (compiled)
    """A standard normal draw for the key (Box–Muller on two uniforms of slots 2·slot and 2·slot + 1)."""
    u1 = uniform(seed, step, stream, 2 * slot)
    u2 = uniform(seed, step, stream, 2 * slot + 1)
    return math.sqrt(-2.0 * math.log(1.0 - u1)) * math.cos(2.0 * math.pi * u2)


@njit(cache=True)
def _uniform_many(seeds, step, stream, slots):  # pragma: no cover (compiled)
    out = np.empty((seeds.shape[0], slots))
    for b in range(seeds.shape[0]):
        for s in range(slots):
            out[b, s] = uniform(seeds[b], step, stream, s)
    return out


@njit(cache=True)
def _normal_many(seeds, step, stream, slots):  # pragma: no cover (compiled)
    out = np.empty((seeds.shape[0], slots))
    for b in range(seeds.shape[0]):
        for s in range(slots):
            out[b, s] = normal(seeds[b], step, stream, s)
    return out


def uniforms(seeds: np.ndarray, step: int, stream: int, slots: int) -> np.ndarray:
    """Uniform draws [B, slots] for each variant's seed at one step (for tests and NumPy callers)."""
    return _uniform_many(np.asarray(seeds, dtype=np.int64), step, stream, slots)


def normals(seeds: np.ndarray, step: int, stream: int, slots: int) -> np.ndarray:
    """Standard normal draws [B, slots] for each variant's seed at one step."""
    return _normal_many(np.asarray(seeds, dtype=np.int64), step, stream, slots)
