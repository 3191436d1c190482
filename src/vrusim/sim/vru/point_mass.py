"""The built-in VRU motion model, `point_mass`: its per-VRU parameters (its step, `vrusim.sim.vru.motion`, is
attached to the same entry when that module is imported: it needs the packed batch, which needs this module).

A path-constrained point mass driven toward its top speed (docs/models.md, "VRU model"): top speed, maximum
acceleration and speed time constant, the speed held before the trigger, and an optional braking phase.
"""

from __future__ import annotations

import math

from vrusim.scenario.schema import Vru
from vrusim.sim.vru.registry import POINT_MASS, VruMotionRow, register_vru_motion


def pack_point_mass(vru: Vru) -> VruMotionRow:
    """One VRU's point-mass parameters (type defaults applied by the schema)."""
    brake = vru.brake
    return VruMotionRow(
        vru.speed_mps,
        vru.accel_mps2,
        vru.speed_time_constant_s,
        vru.initial_speed_mps,
        math.inf if brake is None else brake.after_trigger_s,
        0.0 if brake is None else brake.decel_mps2,
    )


register_vru_motion(POINT_MASS, pack_point_mass)
