"""The shaped VRU motion models, `cubic` and `sinusoidal`: a point mass whose speed changes follow a smooth shape
instead of a constant rate (OpenSCENARIO `dynamicsShape` cubic and sinusoidal; docs/models.md, "VRU model").

They read the same per-VRU parameters as `point_mass` (`VruMotionRow`: top speed, `max_accel_mps2` as the mean
rate of a speed change, initial speed, braking delay and mean deceleration) and fire triggers the same way. A
change from v0 to v1 takes T = |v1 - v0| / mean rate and follows v(t) = v0 + (v1 - v0) h(s), s = (t - t0) / T,
with h(s) = 3s^2 - 2s^3 (cubic) or (1 - cos(pi s)) / 2 (sinusoidal); the braking phase follows the same shape
from the speed at its start. Their step is the compiled kernel in `vrusim.sim.vru.shaped_motion`.
"""

from __future__ import annotations

import math

from vrusim.errors import UserInputError
from vrusim.scenario.schema import Vru
from vrusim.sim.vru.point_mass import pack_point_mass
from vrusim.sim.vru.registry import VruMotionRow, register_vru_motion

CUBIC, SINUSOIDAL = "cubic", "sinusoidal"
SHAPE_CODES = {CUBIC: 0, SINUSOIDAL: 1}
"""Each shaped model's code in the compiled step."""
PEAK_TO_MEAN_RATE = {CUBIC: 1.5, SINUSOIDAL: math.pi / 2}
"""Peak rate of a shaped speed change over its mean rate |v1 - v0| / T: max h'(s) = h'(1/2) (1.5 for the cubic,
pi/2 for the sinusoid)."""


def shape_fraction(shape: str, s: float) -> float:
    """h(s): the fraction of a speed change done at fraction s of its duration (0 <= s <= 1)."""
    return s * s * (3.0 - 2.0 * s) if shape == CUBIC else (1.0 - math.cos(math.pi * s)) / 2.0


def shape_integral(shape: str, s: float) -> float:
    """The integral of h from 0 to s (1/2 at s = 1 for both shapes)."""
    return s**3 - s**4 / 2.0 if shape == CUBIC else (s - math.sin(math.pi * s) / math.pi) / 2.0


def _pack_shaped(name: str):
    def pack(vru: Vru) -> VruMotionRow:
        """One VRU's parameters, as `point_mass` packs them; a speed time constant is refused (the shape is the
        whole speed change)."""
        if vru.speed_time_constant_s != 0.0:
            raise UserInputError(
                f"vrus[].speed_time_constant_s: VRU motion model {name!r} shapes its speed changes itself; give 0"
            )
        return pack_point_mass(vru)

    return pack


for _name in SHAPE_CODES:
    register_vru_motion(_name, _pack_shaped(_name))
