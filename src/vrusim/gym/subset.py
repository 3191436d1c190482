"""A subset of a packed batch: the same per-variant parameters for chosen variants, without packing again."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from vrusim.sim.compaction import take as take_variants
from vrusim.sim.params import BatchParams


def take(params: BatchParams, index: np.ndarray) -> BatchParams:
    """The variants `index` of `params`, with the step count of their longest duration (as `pack` counts it)."""
    sub = take_variants(params, np.asarray(index, dtype=np.int64))
    return dataclasses.replace(sub, n_steps=math.ceil(sub.duration_s.max() / params.dt_s - 1e-9))
