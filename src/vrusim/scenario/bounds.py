"""Physical bounds on user-written fields, chosen by the unit in the field's name (docs/limits.md).

A field `x_m` or `y_m` is a coordinate (limit `coordinate_m`), any other field ending in `_m` a length or
distance (`length_m`), `_mps` a speed (`speed_mps`), `_mps2` an acceleration (`accel_mps2`); a rate or gain
`..._per_<unit>` (`heading_gain_per_m`, 1/m) is none of these. A huge but
finite number (1e308 m, a point 10^15 m away) would otherwise pass validation and then overflow or allocate
without end. `StrictModel` checks every field this way after its own validation, so the error names the
field's exact path (`ego.route.length_m`, `vrus[0].path[3].x_m`); the limits change with their variables
`VRUSIM_LIMIT_<NAME>`.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence

from vrusim.limits import excess, limit

COORDINATE_FIELDS = frozenset({"x_m", "y_m"})
"""Names of coordinate fields (a world-frame position, m)."""

SUFFIX_LIMITS = (("_mps2", "accel_mps2"), ("_mps", "speed_mps"), ("_m", "length_m"))
"""(name suffix, limit) pairs, the first match wins."""
BOUND_LIMITS = ("coordinate_m", "length_m", "speed_mps", "accel_mps2")
"""Every limit a field can be bound by."""


def bound_of(field: str) -> str | None:
    """The limit that bounds a field named `field` (`coordinate_m`, `length_m`, `speed_mps`, `accel_mps2`),
    or None for a field without a physical bound."""
    if field in COORDINATE_FIELDS:
        return "coordinate_m"
    if "_per_" in field:  # a quantity per unit: heading_gain_per_m is in 1/m, not a length
        return None
    for suffix, name in SUFFIX_LIMITS:
        if field.endswith(suffix):
            return name
    return None


def value_excess(limit_name: str, value: object) -> str | None:
    """Why `value` (a number, or a list of numbers) is beyond limit `limit_name`, or None."""
    numbers = value if isinstance(value, tuple | list) else (value,)
    bound = limit(limit_name)  # read once per value: validation checks every bounded field of every model
    for number in numbers:
        if isinstance(number, int | float) and not isinstance(number, bool) and abs(number) > bound:
            return excess(limit_name, number)
    return None


def bound_excess(field: str, value: object) -> str | None:
    """Why a value of field `field` is beyond its physical bound, or None (within it, or no bound)."""
    name = bound_of(field)
    return None if name is None else value_excess(name, value)


def path_length_m(points: Sequence[tuple[float, float]]) -> float:
    """Total length of the polyline through `points` (x, y in m), m."""
    return sum(math.dist(a, b) for a, b in itertools.pairwise(points))


def path_length_excess(points: Sequence[tuple[float, float]]) -> str | None:
    """Why a polyline through `points` is too long (limit `length_m` on its total length), or None."""
    reason = excess("length_m", path_length_m(points))
    return None if reason is None else f"total length {reason}"
