"""AEB for a reversing ego (Euro NCAP LSC26 CPMRCm / CPMRCs, §3.2.2), the AEB planner on its mirrored frame.

A reversing ego is simulated as the body mirrored front to back (docs/models.md, "Reversing"): its leading edge
is the real rear bumper, its route runs backwards and the sector sensor sits at the rear bumper. The AEB
planner's route TTC therefore already looks behind the car, and its stages hold the brake while the VRU is in
the path, through a standstill, as LSC26 §5.1 requires ("the system may not release the brakes after an
intervention, unless the threat has left the vehicle path"). `reverse_aeb` is that planner with its own
parameter model, for reversing egos only: a variant whose `ego.reverse` is false is a UserInputError.
"""

from __future__ import annotations

from vrusim.errors import UserInputError
from vrusim.planners.aeb import AebParams, AebPlanner
from vrusim.sim.params import BatchParams


class ReverseAebParams(AebParams):
    """Parameters of the reversing AEB (YAML `planner.params`): those of `aeb`, same defaults."""


class ReverseAebPlanner(AebPlanner):
    """The AEB stages on a reversing ego (its leading edge is the real rear bumper)."""

    params_model = ReverseAebParams

    def reset(self, params: BatchParams) -> None:
        """Refuse forward-driving variants, then reset as the AEB planner."""
        for name, reverse in zip(params.names, params.reverse, strict=True):
            if not reverse:
                raise UserInputError(f"{name}: ego.reverse: planner 'reverse_aeb' needs a reversing ego (true)")
        super().reset(params)
