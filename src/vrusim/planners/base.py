"""The planner interface: any object with `reset` and `act` can drive the ego.

A planner is created once, `reset(params)` is called before a batch starts (it may read per-variant parameters
from `params.planner_params[b]`, read-only mappings of the YAML `planner.params`), and `act(observation)` is
called every step and returns the commanded longitudinal acceleration per variant, m/s^2, shape [B].

Three optional attributes are declared, with their defaults, on `PlannerBase`: planners with discrete modes
set `mode_names` (a tuple of names) and `mode` (int array [B], index into `mode_names`) so that the engine
records every transition with its time; planners that warn the driver set `warning` (bool array [B]). A planner
need not subclass `PlannerBase`: the engine and the Euro NCAP assessment read these attributes only through
`planner_mode_names`, `planner_mode` and `planner_warning`, which fall back to the declared defaults.
"""

from __future__ import annotations

from typing import ClassVar, Protocol, runtime_checkable

import numpy as np

from vrusim.sim.compaction import take_members
from vrusim.sim.observation import Observation
from vrusim.sim.params import BatchParams


@runtime_checkable
class Planner(Protocol):
    """Longitudinal motion planner for a batch of egos."""

    def reset(self, params: BatchParams) -> None:
        """Prepare for a new batch."""

    def act(self, observation: Observation) -> np.ndarray:
        """Commanded acceleration per variant, m/s^2."""


class PlannerBase:
    """A base class for planners that declares the optional attributes the engine reads, with their defaults.

    Subclasses implement `reset` and `act`, and set `mode` / `warning` (per-variant arrays) in `reset` if they
    have modes / warn. A `compact` method must be defined on the subclass itself (the engine only compacts
    planners whose own class defines one).
    """

    mode_names: ClassVar[tuple[str, ...]] = ("running",)
    """Names of the planner's modes; `mode` indexes into them (index 0: the initial mode)."""
    mode: np.ndarray | None = None
    """Current mode per variant, int array [B], or None: no modes (nothing recorded)."""
    warning: np.ndarray | None = None
    """Forward-collision warning per variant, bool array [B] (true while on), or None: the planner never warns."""

    def reset(self, params: BatchParams) -> None:
        """Prepare for a new batch."""
        raise NotImplementedError

    def act(self, observation: Observation) -> np.ndarray:
        """Commanded acceleration per variant, m/s^2."""
        raise NotImplementedError


_DEFAULTS = {name: getattr(PlannerBase, name) for name in ("mode_names", "mode", "warning")}


def _declared(planner: object, name: str):
    """`planner.name`, or `PlannerBase`'s default for planners that neither subclass it nor set the attribute."""
    return getattr(planner, name, _DEFAULTS[name])


def planner_mode_names(planner: object) -> tuple[str, ...]:
    """The planner's mode names (default `("running",)`)."""
    return tuple(_declared(planner, "mode_names"))


def planner_mode(planner: object) -> np.ndarray | None:
    """The planner's current mode per variant [B], or None if it has no modes."""
    return _declared(planner, "mode")


def planner_warning(planner: object) -> np.ndarray | None:
    """The planner's warning per variant [B], or None if it never warns."""
    return _declared(planner, "warning")


class HoldSpeedPlanner(PlannerBase):
    """The `none` planner: commands zero acceleration, so the ego holds its start speed (protocol checks)."""

    mode_names = ("hold",)

    def reset(self, params: BatchParams) -> None:
        """Allocate the mode array."""
        self.mode = np.zeros(params.size, dtype=np.int8)

    def compact(self, index: np.ndarray) -> None:
        """Keep only variants `index` (the engine drops stopped ones)."""
        take_members(self, index)

    def act(self, observation: Observation) -> np.ndarray:
        """Zero acceleration for every variant."""
        return np.zeros(observation.ego_speed_mps.shape)
