"""Where the Euro NCAP turning paths lie in the world frame of `ncap.build`, and where a VUT point on them is.

World frame: the VUT approaches along +x in the right lane (centre line y = LANE_Y_M) of a junction centred on
the origin. A protocol turn (clothoid – arc – clothoid, FC26 §1.2.1) is placed so that the rear axle leaves it
on the centre line of the right lane of the road turned into.
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from vrusim.geometry.paths import SAMPLE_SPACING_M, PathSpec, sample_path
from vrusim.ncap.protocol import LANE_WIDTH_M, TURN_PATHS
from vrusim.ncap.test_case import VUT
from vrusim.scenario.routes import ego_route_spec, route_spec
from vrusim.scenario.schema import Ego, Route

LANE_Y_M = -LANE_WIDTH_M / 2
"""Centre line of the VUT's approach lane, m."""
EXIT_LENGTH_M = 25.0
"""Route beyond the nominal impact point (or the end of a turn), m."""


def vut_geometry(reverse: bool) -> tuple[float, float]:
    """(rear axle → leading edge, rear axle → rectangle centre) in the direction of travel, m."""
    length, wheelbase, rear = VUT["length_m"], VUT["wheelbase_m"], VUT["rear_overhang_m"]
    trailing = length - wheelbase - rear if reverse else rear
    return length - trailing, length / 2 - trailing


def route_samples(ego: dict) -> np.ndarray:
    """The sampled rear-axle route of an ego mapping: [N, 5] x, y, tangent x, tangent y, curvature."""
    return sample_path(ego_route_spec(Ego.model_validate(ego)))


def route_crossing(
    samples: np.ndarray, along_m: float, left_m: float, point: np.ndarray, direction: np.ndarray
) -> tuple[float, np.ndarray]:
    """First route station (m) where the VUT's point (`along_m` ahead of the rear axle, `left_m` left of the
    centre line) crosses the line through `point` along `direction`, and that crossing point (world, m)."""
    xy, tangent = samples[:, :2], samples[:, 2:4]
    normal = np.column_stack([-tangent[:, 1], tangent[:, 0]])
    moving = xy + along_m * tangent + left_m * normal
    rel = moving - point
    side = direction[0] * rel[:, 1] - direction[1] * rel[:, 0]
    change = np.flatnonzero(np.sign(side[:-1]) * np.sign(side[1:]) <= 0)
    if len(change) == 0:
        raise ValueError("the VUT route never crosses the target path")
    i = int(change[0])
    frac = side[i] / (side[i] - side[i + 1]) if side[i] != side[i + 1] else 0.0
    return (i + frac) * SAMPLE_SPACING_M, moving[i] + frac * (moving[i + 1] - moving[i])


def ncap_turn_route(side: str, speed_kph: float, turn_at_m: float, exit_m: float) -> Route:
    """The protocol's turning route for `side` ("farside" = left, "nearside" = right) at `speed_kph`:
    `turn_at_m` of straight approach, the clothoid – arc – clothoid turn, `exit_m` of straight exit."""
    if (side, speed_kph) not in TURN_PATHS:
        raise ValueError(f"no Euro NCAP turn for {side} at {speed_kph:g} km/h; known: {sorted(TURN_PATHS)}")
    path = TURN_PATHS[side, speed_kph]
    alpha = math.radians(path.clothoid_angle_deg)
    clothoid_m = 2 * alpha / (1 / path.entry_radius_m + 1 / path.radius_m)
    turn_m = 2 * clothoid_m + path.radius_m * math.radians(path.arc_angle_deg)
    return Route(
        kind="left" if side == "farside" else "right",
        turn_at_m=turn_at_m,
        radius_m=path.radius_m,
        angle_deg=path.arc_angle_deg,
        clothoid_angle_deg=path.clothoid_angle_deg,
        clothoid_entry_radius_m=path.entry_radius_m,
        length_m=turn_at_m + turn_m + exit_m,
    )


@lru_cache(maxsize=64)
def _placed_turn_cached(side: str, speed_kph: float) -> tuple[np.ndarray, float]:
    route = ncap_turn_route(side, speed_kph, 0.0, EXIT_LENGTH_M)
    samples = sample_path(route_spec(route, 0.0, 0.0, 0.0))
    exit_x = samples[math.ceil(route.turn_length_m / SAMPLE_SPACING_M), 0]  # where the exit straight begins
    turn_start_x = (LANE_WIDTH_M / 2 if side == "farside" else -LANE_WIDTH_M / 2) - exit_x
    samples[:, 0] += turn_start_x
    samples[:, 1] += LANE_Y_M
    samples.setflags(write=False)
    return samples, float(turn_start_x)


def placed_turn(side: str | None, speed_kph: float) -> tuple[np.ndarray, float]:
    """The sampled rear-axle route of the protocol turn from its start (read-only, cached), placed so the rear
    axle leaves it on the centre line of the right lane of the road turned into; and x of the turn start."""
    if side is None:
        raise ValueError("a turning test needs its turn side")
    return _placed_turn_cached(side, float(speed_kph))


def placed_turn_spec(side: str, speed_kph: float) -> PathSpec:
    """The exact rear-axle path of `placed_turn` (for poses between its samples)."""
    _, turn_start_x = placed_turn(side, speed_kph)
    return route_spec(ncap_turn_route(side, speed_kph, 0.0, EXIT_LENGTH_M), turn_start_x, LANE_Y_M, 0.0)
