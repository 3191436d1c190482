"""VRU motion models by name: how a model packs one scenario VRU, and how it moves a batch's VRUs one step.

A scenario VRU names its model in `vrus[k].motion` (default `point_mass`). `vrusim.sim.vru.point_mass` registers
the built-in, `point_mass` (the path-constrained point mass the paper and Euro NCAP describe; its step is the
compiled kernel in `vrusim.sim.vru.motion`). Packing (`vrusim.sim.params.pack`) asks the registry for each VRU's
model and never reads the motion fields of a VRU itself; the engine steps a batch's VRUs with its model's
`advance` (one model per batch). See docs/models.md, "VRU model".
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import NamedTuple

from vrusim.scenario.schema import Vru

AdvanceVrus = Callable[..., None]
"""`advance(params: BatchParams, vrus: VruState, t_s, front_x_m, front_y_m, ego_speed_mps, ego_station_m)`: fire
triggers from the ego state at t_s, then move every VRU of the batch by one step, in place (arrays [B]; `vrus`
[B, K]). Written without the types: this module sits below the packed batch (`vrusim.sim.params` imports it)."""

POINT_MASS = "point_mass"
"""The built-in model, and the default of `vrus[k].motion`."""


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
    """A registered VRU motion model: its name, how a scenario VRU packs into a `VruMotionRow`, and its step."""

    name: str
    pack: Callable[[Vru], VruMotionRow]
    advance: AdvanceVrus | None
    """None until the step is attached (`attach_vru_step`; the built-in's module does it when imported)."""


_ENTRIES: dict[str, VruMotionEntry] = {}


def register_vru_motion(
    name: str, pack: Callable[[Vru], VruMotionRow], advance: AdvanceVrus | None = None
) -> VruMotionEntry:
    """Add VRU motion model `name` (`pack` one VRU, `advance` a batch's VRUs one step); return its entry.
    `unregister_vru_motion(name)` removes it."""
    if name in _ENTRIES:
        raise ValueError(f"VRU motion model {name!r} is already registered")
    _ENTRIES[name] = VruMotionEntry(name, pack, advance)
    return _ENTRIES[name]


def attach_vru_step(name: str, advance: AdvanceVrus) -> None:
    """Give registered model `name` its step (for a model whose step module imports the packed batch)."""
    _ENTRIES[name] = VruMotionEntry(name, vru_motion(name).pack, advance)


def unregister_vru_motion(name: str) -> None:
    """Remove VRU motion model `name` (nothing if it is not registered)."""
    _ENTRIES.pop(name, None)


def vru_motion(name: str) -> VruMotionEntry:
    """The registered entry of VRU motion model `name`."""
    entry = _ENTRIES.get(name)
    if entry is None:
        known = sorted(_ENTRIES, key=lambda known_name: (known_name != POINT_MASS, known_name))  # the built-in first
        raise ValueError(f"VRU motion model {name!r} is not registered (known: {', '.join(known)})")
    return entry


def vru_motion_entries() -> dict[str, VruMotionEntry]:
    """The registered VRU motion models by name (a copy)."""
    return dict(_ENTRIES)
