"""The planner interface: any object with `reset` and `act` can drive the ego.

A planner is created once, `reset(params)` is called before a batch starts (it may read per-variant parameters
from `params.planner_params[b]`, read-only mappings of the YAML `planner.params`), and `act(observation)` is
called every step and returns the commanded longitudinal acceleration per variant, m/s^2, shape [B].

Three optional attributes are declared, with their defaults, on `PlannerBase`: planners with discrete modes
set `mode_names` (a tuple of names) and `mode` (int array [B], index into `mode_names`) so that the engine
records every transition with its time; planners that warn the driver set `warning` (bool array [B]); planners
that hold a door closed (door retention, `ego.door`) set `door_hold` (bool array [B]). A planner need not subclass
`PlannerBase`: the engine and the Euro NCAP assessment read these attributes only through `planner_mode_names`,
`planner_mode`, `planner_warning` and `planner_door_hold`, which fall back to the declared defaults.

With a driver schedule (`ego.driver`) the observation carries the driver's request (`driver_accel_mps2`); the
planner's command is what the ego gets, so a planner follows the driver unless it overrides (brakes or cuts the
accelerator). Without one, `has_driver` is false and planners drive by `cruise_speed_mps` as before.
"""

from __future__ import annotations

from typing import ClassVar, Protocol, runtime_checkable

import numpy as np

from vrusim.planners.params import validate_params
from vrusim.scenario.strict import StrictModel
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
    door_hold: np.ndarray | None = None
    """Door retention per variant, bool array [B] (true: the door is held closed this step), or None: never."""

    def reset(self, params: BatchParams) -> None:
        """Prepare for a new batch."""
        raise NotImplementedError

    def act(self, observation: Observation) -> np.ndarray:
        """Commanded acceleration per variant, m/s^2."""
        raise NotImplementedError


_DEFAULTS = {name: getattr(PlannerBase, name) for name in ("mode_names", "mode", "warning", "door_hold")}


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


def planner_door_hold(planner: object) -> np.ndarray | None:
    """The planner's door retention per variant [B], or None if it never holds a door."""
    return _declared(planner, "door_hold")


class NoParams(StrictModel):
    """`planner.params` of a planner without parameters: every field is unknown."""


class HoldSpeedPlanner(PlannerBase):
    """The `none` planner: no function acts. The ego follows its driver's request (`ego.driver`); without a
    driver it commands zero acceleration and holds its start speed (protocol checks)."""

    mode_names = ("hold",)

    def reset(self, params: BatchParams) -> None:
        """Refuse any `planner.params` (it has none) and allocate the mode array."""
        validate_params(NoParams, params)
        self.mode = np.zeros(params.size, dtype=np.int8)

    def compact(self, index: np.ndarray) -> None:
        """Keep only variants `index` (the engine drops stopped ones)."""
        take_members(self, index)

    def act(self, observation: Observation) -> np.ndarray:
        """The driver's request (zero acceleration without a driver) for every variant."""
        if observation.driver_accel_mps2 is None:
            return np.zeros(observation.ego_speed_mps.shape)
        return np.array(observation.driver_accel_mps2, dtype=float)
