"""Turn one Euro NCAP catalogue test (scenario × VUT speed × variant × lighting) into an executable Scenario.

World frame: the VUT approaches along +x in the right lane (y = -lane/2) of a two-lane road (or a junction
centred on the origin). Every target is synchronised so that, if the VUT does not react, its reference point
meets the nominal impact location on the VUT front (rear when reversing): we find the route station where
that point of the VUT crosses the target's path, and start the target — with a route-distance trigger —
exactly its travel time earlier. Geometry choices are listed in docs/euroncap.md.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from vrusim.catalog.ncap_protocol import (
    DUMMIES,
    KPH,
    LANE_WIDTH_M,
    NIGHT_SENSOR_RANGE_FACTOR,
    OBSTRUCTION_CARS,
    TURN_PATHS,
    Cell,
    Dummy,
    NcapScenario,
)
from vrusim.scenario.paths import ego_route_spec, sample_path
from vrusim.scenario.schema import Ego, Route, Scenario

VUT: dict[str, Any] = {
    "length_m": 4.5,
    "width_m": 1.8,
    "wheelbase_m": 2.7,
    "rear_overhang_m": 0.9,
    "max_decel_mps2": 9.0,
    "max_jerk_mps3": 30.0,
    "actuator_lag_s": 0.1,
}
"""Vehicle under test: a mid-size car; braking limits of a modern AEB (our choice, docs/euroncap.md)."""

LANE_Y_M = -LANE_WIDTH_M / 2
"""Centre line of the VUT's approach lane, m."""
LEAD_TIME_S = 4.5
"""The VUT starts at least this long (at test speed) before the nominal impact: T0 = TTC 4 s plus 0.5 s."""
TAIL_TIME_S = 6.0
"""Simulated time after the nominal impact, s (enough to brake to a stop from 130 km/h)."""
EXIT_LENGTH_M = 25.0
"""Route beyond the nominal impact point (or the end of a turn), m."""
RSU_OFFSET_M = (5.0, 5.0)
"""Roadside unit position relative to the nominal impact point, m (our choice)."""
RSU_COMM_RANGE_M, RSU_COVERAGE_M = 250.0, 40.0


@dataclass(frozen=True)
class NcapTest:
    """One executable test of the catalogue."""

    spec: NcapScenario
    cell: Cell
    lighting: str

    @property
    def test_id(self) -> str:
        variant = f"/{self.cell.variant}" if self.cell.variant else ""
        return f"{self.spec.code}/{self.cell.vut_speed_kph:g}kph{variant}/{self.lighting}"

    @property
    def dummy(self) -> Dummy:
        return DUMMIES[self.cell.target or self.spec.target]

    @property
    def impact_location(self) -> float:
        return self.cell.impact_location if self.cell.impact_location is not None else self.spec.impact_location

    @property
    def target_speed_mps(self) -> float:
        kph = self.cell.target_speed_kph if self.cell.target_speed_kph is not None else self.spec.target_speed_kph
        return kph * KPH


@dataclass(frozen=True)
class Nominal:
    """Where and when the target meets the VUT if the VUT does not react (world frame, SI units)."""

    impact_x_m: float
    impact_y_m: float
    time_s: float
    lateral_m: float
    """Nominal impact location on the VUT's leading edge, m left of its centre line."""
    ref_behind_centre_m: float
    """The reference point lies this far behind the footprint centre along the target's heading, m."""
    target_heading_rad: float
    steady_from_s: float
    """Time from which the target holds its steady speed, s (a standing target: 0)."""


@dataclass(frozen=True)
class BuiltTest:
    """A catalogue test as a validated Scenario plus its nominal impact."""

    test: NcapTest
    scenario: Scenario
    nominal: Nominal


def _ego_geometry(reverse: bool) -> tuple[float, float]:
    """(rear axle → leading edge, rear axle → rectangle centre) in the direction of travel, m."""
    length, wheelbase, rear = VUT["length_m"], VUT["wheelbase_m"], VUT["rear_overhang_m"]
    back = length - wheelbase - rear if reverse else rear
    return length - back, length / 2 - back


def _footprint(test: NcapTest) -> tuple[float, float, float]:
    """(radius, footprint centre ahead of the reference point, ...) for the face of the target the VUT meets.

    Returns (radius_m, centre_minus_ref_m, unused): the circle has the target's half width; it sits at the box
    centre for crossing and turning targets, against the rear face for targets ahead, against the front face
    for oncoming ones.
    """
    dummy, layout = test.dummy, test.spec.layout
    radius = dummy.width_m / 2
    if layout in ("longitudinal", "rear"):
        centre, use = radius, "longitudinal"
    elif layout == "oncoming":
        centre, use = dummy.length_m - radius, "turning"
    else:
        centre = dummy.length_m / 2
        use = "turning" if layout == "turning" and "turning" in dummy.ref_from_rear_m else "crossing"
    return radius, centre - dummy.ref_from_rear_m[use], 0.0


def _route_samples(ego: dict) -> np.ndarray:
    """The sampled rear-axle route of an ego mapping: [N, 5] x, y, tangent x, tangent y, curvature."""
    return sample_path(ego_route_spec(Ego.model_validate(ego)))


def _crossing(samples: np.ndarray, lead_m: float, lateral_m: float, point, direction) -> tuple[float, np.ndarray]:
    """First route station (m) where the VUT's point `lateral_m` left of the centre of its leading edge crosses
    the line through `point` along `direction`, and that crossing point (world, m)."""
    xy, tangent = samples[:, :2], samples[:, 2:4]
    normal = np.column_stack([-tangent[:, 1], tangent[:, 0]])
    edge = xy + lead_m * tangent + lateral_m * normal
    rel = edge - np.asarray(point, dtype=float)
    side = direction[0] * rel[:, 1] - direction[1] * rel[:, 0]
    change = np.flatnonzero(np.sign(side[:-1]) * np.sign(side[1:]) <= 0)
    if len(change) == 0:
        raise ValueError("the VUT route never crosses the target path")
    i = int(change[0])
    frac = side[i] / (side[i] - side[i + 1]) if side[i] != side[i + 1] else 0.0
    spacing = float(np.hypot(*(samples[1, :2] - samples[0, :2])))
    return (i + frac) * spacing, edge[i] + frac * (edge[i + 1] - edge[i])


def ncap_turn_route(side: str, speed_kph: float, turn_at_m: float, exit_m: float) -> Route:
    """The protocol's turning route for `side` ("farside" = left, "nearside" = right) at `speed_kph`:
    `turn_at_m` of straight approach, the clothoid – arc – clothoid turn, `exit_m` of straight exit."""
    if (side, speed_kph) not in TURN_PATHS:
        raise ValueError(f"no Euro NCAP turn for {side} at {speed_kph:g} km/h; known: {sorted(TURN_PATHS)}")
    path = TURN_PATHS[side, speed_kph]
    fields = {
        "kind": "left" if side == "farside" else "right",
        "turn_at_m": turn_at_m,
        "radius_m": path.radius_m,
        "angle_deg": path.arc_angle_deg,
        "clothoid_angle_deg": path.clothoid_angle_deg,
        "clothoid_entry_radius_m": path.entry_radius_m,
    }
    turn_length = Route(**fields, length_m=1e12).turn_length_m
    return Route(**fields, length_m=turn_at_m + turn_length + exit_m)


def _turn_route(test: NcapTest, approach_m: float, after_m: float) -> dict:
    """Route mapping of a turning test: `approach_m` straight, the protocol turn, `after_m` straight."""
    return ncap_turn_route(test.spec.turn, test.cell.vut_speed_kph, approach_m, after_m).model_dump()


def _target_line(test: NcapTest) -> tuple[tuple[float, float], tuple[float, float]]:
    """A point on the target's path and its unit direction (world frame)."""
    spec = test.spec
    if spec.layout == "crossing":
        junction_x = LANE_WIDTH_M / 2 if "junction" in spec.tags else 0.0
        if spec.side == "farside":
            return (-junction_x, 0.0), (0.0, -1.0)
        return (junction_x, 0.0), (0.0, 1.0)
    if spec.layout in ("turning", "oncoming"):
        y = spec.target_line_m if spec.turn == "farside" else -spec.target_line_m
        forward = spec.walks_with_vut and spec.layout == "turning"
        return (0.0, y), ((1.0, 0.0) if forward else (-1.0, 0.0))
    return (0.0, 0.0), (0.0, 1.0)  # longitudinal, rear, reverse: the impact plane x = 0


def _target_travel(test: NcapTest) -> tuple[str, float]:
    """How the target moves: ("rest", distance accelerating and steady), ("flying", 0), ("still", 0),
    ("braking", 0)."""
    spec = test.spec
    if spec.layout == "rear":
        return ("braking", 0.0) if spec.headway_s > 0 else ("still", 0.0)
    if test.target_speed_mps == 0.0:
        return "still", 0.0
    if spec.layout == "oncoming" or "flying" in spec.tags:
        return "flying", 0.0
    return "rest", spec.accel_distance_m


def _time_to_impact_from_rest(distance_m: float, accel_m: float, speed_mps: float) -> float:
    """Time to cover `distance_m` from rest: uniform acceleration over `accel_m`, then constant speed, s."""
    if accel_m <= 0:
        return distance_m / speed_mps
    return 2 * accel_m / speed_mps + (distance_m - accel_m) / speed_mps


def build_test(test: NcapTest, planner: str = "fsm", v2x: bool = False) -> BuiltTest:
    """The executable Scenario of one catalogue test, and its nominal impact."""
    spec = test.spec
    v = test.cell.vut_speed_kph * KPH
    reverse = spec.layout == "reverse"
    lead, back = _ego_geometry(reverse)
    lateral = (test.impact_location - 0.5) * VUT["width_m"]
    point, direction = _target_line(test)
    kind, accel_m = _target_travel(test)
    v_target = test.target_speed_mps
    radius, centre_ahead, _ = _footprint(test)
    heading = math.atan2(direction[1], direction[0])

    # where the target meets the VUT, and how long before that it must start
    if spec.layout in ("turning", "oncoming"):
        probe = _turn_probe(test, v, lead, lateral, point, direction)
        impact, station_from_turn, turn_start_x = probe
    else:
        travel = -1.0 if reverse else 1.0
        impact = np.array([point[0], LANE_Y_M + travel * lateral])
    if kind == "rest":
        if spec.layout == "crossing":
            start_y = LANE_Y_M - spec.lateral_offset_m * direction[1]
            start = np.array([point[0], start_y])
        elif spec.layout == "longitudinal":
            heading = 0.0
            direction = (1.0, 0.0)
            start = impact - np.array(direction) * (spec.accel_distance_m + spec.steady_distance_m)
        else:  # turning pedestrians and reversing: lateral_offset_m is the start → impact distance
            if reverse:
                direction = (0.0, -1.0)
                heading = -math.pi / 2
            start = impact - np.array(direction) * spec.lateral_offset_m
        distance = float(np.hypot(*(impact - start)))
        target_time = _time_to_impact_from_rest(distance, accel_m, v_target)
    else:
        target_time = 0.0
    if spec.layout in ("longitudinal", "rear"):
        heading, direction = 0.0, (1.0, 0.0)
    if spec.layout == "reverse" and kind == "still":
        heading, direction = -math.pi / 2, (0.0, -1.0)
    needed_s = max(LEAD_TIME_S, target_time + 0.5)

    # the VUT and its route; `station` is the rear-axle route distance at the nominal impact
    if spec.layout in ("turning", "oncoming"):
        approach = max(v * needed_s - station_from_turn, 5.0)
        ego = {
            **VUT,
            "start": {"x_m": turn_start_x - approach + back, "y_m": LANE_Y_M, "heading_deg": 0.0},
            "cruise_speed_mps": v,
            "route": _turn_route(test, approach, EXIT_LENGTH_M),
        }
        station = approach + station_from_turn
    else:
        station = 10.0 if reverse else max(v * needed_s, 5.0)
        travel = -1.0 if reverse else 1.0
        centre_x = point[0] - travel * (station + lead - back)
        route_length = station + EXIT_LENGTH_M
        ego = {
            **VUT,
            "start": {"x_m": centre_x, "y_m": LANE_Y_M, "heading_deg": 0.0},
            "cruise_speed_mps": v,
            "route": {"kind": "straight", "length_m": route_length},
            "reverse": reverse,
        }
        if not reverse:
            del ego["reverse"]
    impact_time = station / v

    # the target's start, profile and trigger
    vru: dict[str, Any] = {"type": test.dummy.vru_type.value, "radius_m": radius, "speed_time_constant_s": 0.0}
    steady_from = 0.0
    if kind == "rest":
        trigger_station = station - v * target_time
        if trigger_station < -1e-9:
            raise ValueError(f"{test.test_id}: the VUT route is too short to synchronise the target")
        vru.update(
            top_speed_mps=v_target,
            max_accel_mps2=v_target * v_target / (2 * accel_m) if accel_m > 0 else 1e3,
            trigger={"ego_route_m": max(trigger_station, 0.0)},
        )
        steady_from = impact_time - target_time + 2 * accel_m / v_target
    elif kind == "flying":
        start = impact - np.array(direction) * v_target * impact_time
        vru.update(top_speed_mps=v_target, initial_speed_mps=v_target, trigger={"at_time_s": 0.0})
    elif kind == "still":
        start = impact.copy()
        vru.update(top_speed_mps=0.0)
    else:  # braking motorcycle ahead: same speed, headway, brakes 1.5 s into the run
        brake_after = 1.5
        front_x0 = point[0] - station
        start = np.array([front_x0 + v * spec.headway_s, LANE_Y_M + lateral])
        gap = v * spec.headway_s
        catch_up = math.sqrt(2 * gap / spec.target_decel_mps2)
        impact_time = brake_after + min(catch_up, v / spec.target_decel_mps2)
        travelled = v * impact_time - 0.5 * spec.target_decel_mps2 * (impact_time - brake_after) ** 2
        impact = start + np.array([travelled, 0.0])
        ego["route"]["length_m"] = float(impact[0] - front_x0) + EXIT_LENGTH_M
        vru.update(
            top_speed_mps=v,
            initial_speed_mps=v,
            trigger={"at_time_s": 0.0},
            brake={"after_trigger_s": brake_after, "decel_mps2": spec.target_decel_mps2},
        )
    centre = start + np.array(direction) * centre_ahead
    vru.update(start={"x_m": float(centre[0]), "y_m": float(centre[1])}, heading_deg=math.degrees(heading))

    sensor_range = 20.0 * (NIGHT_SENSOR_RANGE_FACTOR if test.lighting == "night" else 1.0)
    junction = "junction" in spec.tags or spec.layout in ("turning", "oncoming")
    scenario = Scenario.model_validate(
        {
            "name": test.test_id,
            "description": f"Euro NCAP {spec.code}: {spec.description}",
            "road": {"layout": "intersection" if junction else "straight", "lane_width_m": LANE_WIDTH_M},
            "ego": ego,
            "sensor": {"range_m": sensor_range, "fov_deg": 120.0},
            "v2x": {
                "enabled": v2x,
                "rsu": {"x_m": float(impact[0] + RSU_OFFSET_M[0]), "y_m": float(impact[1] + RSU_OFFSET_M[1])},
                "comm_range_m": RSU_COMM_RANGE_M,
                "coverage_range_m": RSU_COVERAGE_M,
            },
            "planner": {"name": planner},
            "vrus": [vru],
            "sim": {"dt_s": 0.01, "duration_s": round(impact_time + TAIL_TIME_S, 2)},
        }
        | ({"obstacles": obstruction_cars(spec.obstruction, point, test.dummy)} if spec.obstruction else {})
    )
    nominal = Nominal(
        float(impact[0]), float(impact[1]), impact_time, lateral, centre_ahead, heading, max(steady_from, 0.0)
    )
    return BuiltTest(test, scenario, nominal)


def _turn_probe(test: NcapTest, v: float, lead: float, lateral: float, point, direction):
    """Place the turn so the rear axle leaves it on the centre line of the right lane of the road turned into.

    Returns (impact point, route distance from the start of the turn to the impact, x of the turn start).
    """
    back = _ego_geometry(False)[1]
    probe = {
        **VUT,
        "start": {"x_m": back, "y_m": 0.0, "heading_deg": 0.0},
        "cruise_speed_mps": max(v, 0.1),
        "route": _turn_route(test, 0.0, EXIT_LENGTH_M),
    }
    samples = _route_samples(probe)
    end = samples[np.argmin(np.abs(samples[:, 2]) + 10.0 * (np.abs(samples[:, 4]) > 0))]
    exit_x = LANE_WIDTH_M / 2 if test.spec.turn == "farside" else -LANE_WIDTH_M / 2
    turn_start_x = exit_x - end[0]
    samples[:, 0] += turn_start_x
    samples[:, 1] += LANE_Y_M
    station, impact = _crossing(samples, lead, lateral, point, direction)
    return impact, station, turn_start_x


def obstruction_cars(kind: str, path_point, dummy: Dummy) -> list[dict]:
    """Parked obstruction vehicles of a scenario, as Scenario `obstacles` mappings (docs/euroncap.md)."""
    small, suv = OBSTRUCTION_CARS["small car"], OBSTRUCTION_CARS["SUV"]
    half_target = dummy.width_m / 2
    if kind == "CPNCO":
        # parallel to the VUT path on the nearside, 1.0 m clear of the VUT side; small car's front 1.0 m before
        # the child's path edge, SUV 1.0 m behind it
        front = path_point[0] - half_target - 1.0
        cars = [("small car", small, front - small[0] / 2), ("SUV", suv, front - small[0] - 1.0 - suv[0] / 2)]
        return [
            {
                "kind": name,
                "centre": {"x_m": x, "y_m": LANE_Y_M - (VUT["width_m"] / 2 + 1.0 + size[1] / 2), "heading_deg": 0.0},
                "length_m": size[0],
                "width_m": size[1],
            }
            for name, size, x in cars
        ]
    # junction cases: SUV nearest the junction, then the small car 0.2 m behind it, parallel to the side road,
    # on the VUT's side of the cyclist's path
    end_from_lane, clearance = {"CBNA": (17.0, 1.0), "CBNAO": (3.55, 4.8), "CBFA": (22.0, 1.0)}[kind]
    outward = -1.0 if kind != "CBFA" else 1.0  # nearside arm: y < 0; farside arm: y > 0
    end_y = LANE_Y_M + outward * end_from_lane
    toward_vut = -1.0  # the VUT approaches from -x
    cars, along = [], 0.0
    for name, size in (("SUV", suv), ("small car", small)):
        centre_y = end_y + outward * (along + size[0] / 2)
        centre_x = path_point[0] + toward_vut * (half_target + clearance + size[1] / 2)
        cars.append(
            {
                "kind": name,
                "centre": {"x_m": centre_x, "y_m": centre_y, "heading_deg": 90.0},
                "length_m": size[0],
                "width_m": size[1],
            }
        )
        along += size[0] + 0.2
    return cars
