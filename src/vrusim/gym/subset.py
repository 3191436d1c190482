"""A subset of a packed batch: the same per-variant parameters for chosen variants, without packing again."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from vrusim.sim.batch import BatchParams
from vrusim.sim.occlusion import ObstacleArrays


def take(params: BatchParams, index: np.ndarray) -> BatchParams:
    """The variants `index` of `params` (path tables are shared; per-variant arrays are indexed)."""
    size = params.size
    index = np.asarray(index, dtype=np.int64)
    changes: dict = {}
    for field in dataclasses.fields(params):
        value = getattr(params, field.name)
        if isinstance(value, np.ndarray) and value.ndim >= 1 and value.shape[0] == size:
            changes[field.name] = value[index]
        elif isinstance(value, ObstacleArrays):
            changes[field.name] = ObstacleArrays(*(np.ascontiguousarray(a[index]) for a in value))
    changes["scenarios"] = [params.scenarios[i] for i in index]
    duration = changes["duration_s"]
    changes["n_steps"] = math.ceil(duration.max() / params.dt_s - 1e-9)  # as `pack` counts them
    return dataclasses.replace(params, **changes)
