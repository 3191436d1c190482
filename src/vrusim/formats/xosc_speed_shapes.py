"""Speed changes with a cubic or sinusoidal `<SpeedActionDynamics dynamicsShape>`: the VRU motion models `cubic`
and `sinusoidal` (`vrusim.sim.vru.shaped`), the ego's refused.

A shaped change maps onto the same fields as a linear one, read as its mean rate |v1 - v0| / T (the model's
`max_accel_mps2` and `brake.decel_mps2`): over a time T, |v1 - v0| / T; over a distance D, |v1^2 - v0^2| / (2 D)
(both shapes cover (v0 + v1) T / 2, as a linear ramp does); at a rate, the rate is the peak rate of change (as
esmini reads it: ASAM OpenSCENARIO XML 1.3 defines the shapes but not a rate for them), so the mean is the rate
over 1.5 (cubic) or pi/2 (sinusoidal). One run moves all its VRUs by one model: the VRUs of a file must all change
speed with one shape (steps go with any); the ego's speed changes are `ego.driver` phases, which are linear.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

from vrusim.errors import UserInputError
from vrusim.formats.xosc_model import RampedSpeedChange, SpeedChange
from vrusim.sim.vru.shaped import SHAPE_CODES

Fail = Callable[[int, str], UserInputError]
"""`fail(line, message)`: the error naming the file and the line."""


def _ramps(changes: Sequence[SpeedChange]) -> list:
    """The ramps of `changes` that are not steps (a time or distance of 0 is a step)."""
    ramps = [c.ramp for c in changes if isinstance(c, RampedSpeedChange)]
    return [r for r in ramps if r.shape != "step" and (r.dimension == "rate" or r.value != 0.0)]


def refuse_shaped_ego(changes: Sequence[SpeedChange], fail: Fail) -> None:
    """Refuse a cubic or sinusoidal speed change of the ego: its changes become linear `ego.driver` phases."""
    for ramp in _ramps(changes):
        if ramp.shape in SHAPE_CODES:
            raise fail(
                ramp.line,
                f"<SpeedActionDynamics> dynamicsShape {ramp.shape} is not supported for the ego: its speed changes "
                "are linear (ego.driver phases); give a linear one",
            )


def vru_speed_shape(vru_changes: dict[str, Sequence[SpeedChange]], fail: Fail) -> str | None:
    """The one shape of the VRUs' speed changes (by entity name): "cubic" or "sinusoidal", None when they are
    linear or steps. A second shape in the file is refused, naming it and where the first was."""
    ramps = sorted((ramp.line, ramp.shape, name) for name, changes in vru_changes.items() for ramp in _ramps(changes))
    for line, shape, name in ramps[1:]:
        first_line, first, first_name = ramps[0]
        if shape != first:
            raise fail(
                line,
                f"<SpeedActionDynamics> dynamicsShape {shape} of entity {name!r}: the VRUs of one file change speed "
                f"with one shape (one VRU motion model per run), and entity {first_name!r} changes it {first} "
                f"(line {first_line})",
            )
    shape = ramps[0][1] if ramps else None
    return shape if shape in SHAPE_CODES else None
