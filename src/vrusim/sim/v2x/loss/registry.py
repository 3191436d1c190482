"""V2X loss models by name: each model's schema, parameter packing and per-message loss decision.

One module per model in this package registers it (`none`, `bernoulli`, `gilbert_elliott`, `distance`); the
channel (`vrusim.sim.v2x.channel`) packs each variant's `loss` through the registry and never names a model.
The built-ins are decided inside the compiled channel kernel (their `code` is below `PLUGIN_CODE`). A model
added from outside with `register_loss_model` gives a NumPy function instead, called once per step for the
variants that use it before the kernel runs: slower, but it needs no change to the compiled code
(docs/models.md, "Adding a loss model").
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from vrusim.scenario.v2x import LossSpec, loss_model_name, register_loss_schema, unregister_loss_schema

PLUGIN_CODE = 64
"""Loss-model codes from here on are plug-ins: the kernel reads their decision from `LossContext`'s result."""


@dataclass(frozen=True)
class LossContext:
    """What a plug-in loss model sees at step `n`. Arrays cover the working set; decide for variants `rows`.

    `generate` [B, K]: whether the RSU generates a message about VRU k now (only those can be lost);
    `generated` [B, K]: messages generated before this step; `params` [B, P]: each variant's packed loss
    parameters (`pack`); `link_distance_m` [B]: RSU–ego distance; `link_state` [B] (int8, -1 at the start): a
    per-variant state the model may update in place for `rows`; `seed` [B]: the variants' seeds (draw with
    `vrusim.sim.rng` keyed by (seed, n, stream, k) to stay batch-independent).
    """

    n: int
    dt_s: float
    rows: np.ndarray
    generate: np.ndarray
    generated: np.ndarray
    seed: np.ndarray
    params: np.ndarray
    link_distance_m: np.ndarray
    link_state: np.ndarray


@dataclass(frozen=True)
class LossModelEntry:
    """A registered loss model: its schema, how a spec packs into a row of floats, its code in the kernel and,
    for plug-ins, the NumPy decision `lost(context) -> bool [len(rows), K]` (message of VRU k lost)."""

    schema: type[LossSpec]
    pack: Callable[[LossSpec], tuple[float, ...]]
    code: int
    lost: Callable[[LossContext], np.ndarray] | None = None

    @property
    def name(self) -> str:
        return loss_model_name(self.schema)


_ENTRIES: dict[str, LossModelEntry] = {}


def register_builtin(schema: type[LossSpec], pack: Callable[[LossSpec], tuple[float, ...]], code: int) -> None:
    """Register a built-in model, decided in the compiled kernel under `code` (`vrusim.sim.v2x.kernels`)."""
    assert code < PLUGIN_CODE
    register_loss_schema(schema)
    _ENTRIES[loss_model_name(schema)] = LossModelEntry(schema, pack, code)


def register_loss_model(
    schema: type[LossSpec],
    pack: Callable[[LossSpec], tuple[float, ...]],
    lost: Callable[[LossContext], np.ndarray],
) -> LossModelEntry:
    """Add a loss model: `loss.model: <name>` then validates with `schema`, packs with `pack` and is decided by
    `lost` (NumPy, once per step). Return its entry; `unregister_loss_model(name)` removes it."""
    name = register_loss_schema(schema)
    if name in _ENTRIES:
        if _ENTRIES[name].schema is schema and _ENTRIES[name].lost is lost:
            return _ENTRIES[name]
        raise ValueError(f"loss model {name!r} is already registered")
    used = {entry.code for entry in _ENTRIES.values()}
    code = next(c for c in range(PLUGIN_CODE, 128) if c not in used)
    entry = LossModelEntry(schema, pack, code, lost)
    _ENTRIES[name] = entry
    return entry


def unregister_loss_model(name: str) -> None:
    """Remove plug-in loss model `name` (its schema too)."""
    unregister_loss_schema(name)
    _ENTRIES.pop(name, None)


def loss_entry(spec: LossSpec) -> LossModelEntry:
    """The registered entry of a loss spec's model."""
    entry = _ENTRIES.get(spec.model)
    if entry is None or not isinstance(spec, entry.schema):
        raise ValueError(f"loss model {spec.model!r} has no registered simulation (register_loss_model)")
    return entry


def loss_entries() -> dict[str, LossModelEntry]:
    """The registered loss models by name (a copy)."""
    return dict(_ENTRIES)
