"""VRU motion models by name: each model's packing of one scenario VRU into its per-VRU motion parameters.

`vrusim.sim.vru.point_mass` registers the built-in, `point_mass` (the path-constrained point mass the paper and
Euro NCAP describe; its step is the compiled kernel in `vrusim.sim.vru.motion`). Packing (`vrusim.sim.params.pack`)
asks the registry for the model's entry and never reads the motion fields of a VRU itself
(docs/models.md, "VRU model").
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import NamedTuple

from vrusim.scenario.schema import Vru

POINT_MASS = "point_mass"
"""The built-in model, and the one every VRU moves by."""


class VruMotionRow(NamedTuple):
    """One VRU's packed motion parameters (SI units)."""

    top_speed_mps: float
    max_accel_mps2: float
    tau_s: float
    """Speed time constant (0: constant acceleration to the top speed)."""
    initial_speed_mps: float
    brake_after_s: float
    """Delay from the trigger to a braking phase (inf: none)."""
    brake_decel_mps2: float
    """Deceleration of the braking phase (0: none)."""


@dataclass(frozen=True)
class VruMotionEntry:
    """A registered VRU motion model: its name and how a scenario VRU packs into a `VruMotionRow`."""

    name: str
    pack: Callable[[Vru], VruMotionRow]


_ENTRIES: dict[str, VruMotionEntry] = {}


def register_vru_motion(name: str, pack: Callable[[Vru], VruMotionRow]) -> VruMotionEntry:
    """Add VRU motion model `name`; return its entry. `unregister_vru_motion(name)` removes it."""
    if name in _ENTRIES:
        raise ValueError(f"VRU motion model {name!r} is already registered")
    _ENTRIES[name] = VruMotionEntry(name, pack)
    return _ENTRIES[name]


def unregister_vru_motion(name: str) -> None:
    """Remove VRU motion model `name` (nothing if it is not registered)."""
    _ENTRIES.pop(name, None)


def vru_motion(name: str) -> VruMotionEntry:
    """The registered entry of VRU motion model `name`."""
    entry = _ENTRIES.get(name)
    if entry is None:
        raise ValueError(f"VRU motion model {name!r} is not registered (known: {', '.join(sorted(_ENTRIES))})")
    return entry


def vru_motion_entries() -> dict[str, VruMotionEntry]:
    """The registered VRU motion models by name (a copy)."""
    return dict(_ENTRIES)
