"""Keep only some variants of a running batch: the engine drops variants that have stopped from its working set.

A stopped variant's results are final, yet stepping it costs as much as stepping a running one. Every array
here has the variant on one axis; `take` keeps the rows of `index` (ascending variant numbers of the current
working set) as C-contiguous copies of the same dtype, so the compiled kernels see the same array types.
Stateful parts of the engine (planner, channel, sensor model) take part through a `compact(index)` method.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from vrusim.sim.params import BatchParams
from vrusim.sim.sensing.occlusion import ObstacleArrays
from vrusim.sim.state import EgoState, VruState


def take(array: np.ndarray, index: np.ndarray, axis: int = 0) -> np.ndarray:
    """The rows `index` of `array` along `axis` (the variant axis), as a new C-contiguous array."""
    return np.ascontiguousarray(np.take(array, index, axis=axis))


def take_attributes(owner: object, names: tuple[str, ...], index: np.ndarray, axis: int = 0) -> None:
    """Replace each named array attribute of `owner` (None: left alone) by its rows `index` along `axis`."""
    for name in names:
        value = getattr(owner, name)
        if value is not None:
            setattr(owner, name, take(value, index, axis))


def take_params(params: BatchParams, index: np.ndarray) -> BatchParams:
    """The parameters of variants `index`; path tables are shared (variants address them by offset)."""
    changes: dict[str, object] = {"scenarios": [params.scenarios[i] for i in index]}
    for field in dataclasses.fields(params):
        value = getattr(params, field.name)
        if isinstance(value, ObstacleArrays):
            changes[field.name] = ObstacleArrays(*(take(a, index) for a in value))
        elif isinstance(value, np.ndarray):
            changes[field.name] = take(value, index)
    return dataclasses.replace(params, **changes)


def take_ego(ego: EgoState, index: np.ndarray) -> EgoState:
    """The ego states of variants `index`."""
    return EgoState(*(take(getattr(ego, field.name), index) for field in dataclasses.fields(ego)))


def take_vrus(vrus: VruState, index: np.ndarray) -> VruState:
    """The VRU states of variants `index` (kinematics [6, B, K]: variant on axis 1)."""
    return VruState(
        take(vrus.started, index),
        take(vrus.started_at_s, index),
        take(vrus.station_m, index),
        take(vrus.speed_mps, index),
        take(vrus.kinematics, index, axis=1),
    )


def compactable(*parts: object) -> bool:
    """Whether every part can drop variants: its own class defines `compact(index)`.

    An inherited `compact` does not count: a subclass may keep per-variant state its base does not know.
    """
    return all(callable(vars(type(part)).get("compact")) for part in parts)
