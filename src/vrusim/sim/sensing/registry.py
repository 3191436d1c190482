"""Sensor models by name, in order: the first whose check accepts a batch is the batch's sensor model.

Each entry is (name, applies-to-batch check, factory). `vrusim.sim.sensing.sensor_model` registers the built-ins:
`ideal` (every variant's sensor is ideal: bit-identical to the paper's) and, last, `realistic` (any batch).
`register_sensor_model` adds a model ahead of them (or before another entry), `unregister_sensor_model` removes
it; the engine asks `make_sensor_model` (sensor_model.py) and never names a model (docs/models.md, "Sensor model").
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from vrusim.sim.params import BatchParams


class SensorModel(Protocol):
    """Turns visibility into detections."""

    def reset(self, params: BatchParams) -> None: ...

    def observe(self, step: int, t_s: float, visible: np.ndarray, truth: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(detected [B, K], estimated kinematics [6, B, K]) from this step's visibility and true kinematics."""
        ...

    def age_s(self, step: int, dt_s: float) -> np.ndarray | None:
        """Age of each variant's current report [B], s (None: all 0)."""
        ...


@dataclass(frozen=True)
class SensorModelEntry:
    """A registered sensor model: its name, whether it serves a batch, and how to make one (then `reset`)."""

    name: str
    applies: Callable[[BatchParams], bool]
    factory: Callable[[], SensorModel]


_ENTRIES: list[SensorModelEntry] = []


def register_sensor_model(
    name: str,
    applies: Callable[[BatchParams], bool],
    factory: Callable[[], SensorModel],
    before: str | None = "ideal",
) -> SensorModelEntry:
    """Add a sensor model, checked before entry `before` (default: ahead of the built-ins; None: last).
    Return its entry; `unregister_sensor_model(name)` removes it."""
    if any(entry.name == name for entry in _ENTRIES):
        raise ValueError(f"sensor model {name!r} is already registered")
    names = [e.name for e in _ENTRIES]
    if before is not None and before not in names:
        raise ValueError(f"sensor model {before!r} (to register {name!r} before) is not registered")
    entry = SensorModelEntry(name, applies, factory)
    _ENTRIES.insert(len(_ENTRIES) if before is None else names.index(before), entry)
    return entry


def unregister_sensor_model(name: str) -> None:
    """Remove sensor model `name` (nothing if it is not registered)."""
    _ENTRIES[:] = [entry for entry in _ENTRIES if entry.name != name]


def sensor_model_entries() -> tuple[SensorModelEntry, ...]:
    """The registered sensor models, in the order they are checked."""
    return tuple(_ENTRIES)


def sensor_model_entry(params: BatchParams) -> SensorModelEntry:
    """The first registered sensor model that applies to the batch."""
    for entry in _ENTRIES:
        if entry.applies(params):
            return entry
    raise ValueError("no registered sensor model applies to this batch")
