"""Turn one Euro NCAP catalogue test (scenario × VUT speed × variant × lighting) into an executable Scenario.

World frame: the VUT approaches along +x in the right lane (y = -lane/2) of a two-lane road (or a junction
centred on the origin). Every target is synchronised at first contact (FC26 Definitions, §1.2.5): if the VUT
does not react, the VUT rectangle first touches the target's contact circle with the target's reference point
at the nominal impact location. We find that route station (closed form on straight roads,
`ncap.first_contact` on turns) and start the target — with a route-distance trigger — exactly its travel time
earlier. Geometry choices are listed in docs/euroncap.md.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from vrusim.geometry.paths import SAMPLE_SPACING_M
from vrusim.ncap.build_low_speed import LOW_SPEED_LAYOUTS, build_low_speed
from vrusim.ncap.build_turn_start import stopped_in_turn_ego
from vrusim.ncap.editions.lsc26 import SFS_TURN_PATH_KPH
from vrusim.ncap.first_contact import front_first_contact, side_first_contact_at
from vrusim.ncap.protocol import (
    KPH,
    LANE_WIDTH_M,
    OBSTRUCTION_CARS,
    OBSTRUCTIONS,
    Dummy,
)
from vrusim.ncap.test_case import SENSOR_FOV_DEG, SENSOR_RANGE_M, VUT, BuiltTest, NcapTest, Nominal
from vrusim.ncap.turn_placement import (
    EXIT_LENGTH_M,
    LANE_Y_M,
    ncap_turn_route,
    placed_turn,
    route_crossing,
    vut_geometry,
)
from vrusim.scenario.schema import Scenario

LEAD_TIME_S = 4.5
"""The VUT starts at least this long (at test speed) before the nominal impact: T0 = TTC 4 s plus 0.5 s."""
TAIL_TIME_S = 6.0
"""Simulated time after the nominal impact, s (enough to brake to a stop from 130 km/h)."""
RSU_OFFSET_M = (5.0, 5.0)
"""Roadside unit position relative to the nominal impact point, m (our choice)."""
RSU_COMM_RANGE_M, RSU_COVERAGE_M = 250.0, 40.0
REVERSE_START_M = 10.0
"""A reversing VUT starts with its rear axle this far before the collision point: V23 `Ego_initDist` (the rear
axle, OpenSCENARIO's reference point, is placed 10 m from L; not given by v4.5.1). The bumper starts
REVERSE_START_M - rear overhang away; LSC26 §3.2.2.1 measures reversing gaps from the VUT's rearmost point."""
BRAKE_AFTER_S = 1.5
"""CMRb: the motorcycle starts braking this long into the run (T0 = braking onset - 1 s, FC26)."""
INSTANT_ACCEL_MPS2 = 1e3
"""Acceleration of a target with no acceleration distance (reaches its speed within one step)."""


def _vut_point(test: NcapTest) -> tuple[float, float]:
    """The point of the VUT the target meets, in the simulated frame: (ahead of the rear axle, left of the
    centre line), m. Front impacts: `impact_location` of the width on the leading edge, 0 = the vehicle's
    right edge (ISO 8855; for a reversing VUT, whose simulated frame is mirrored, the body's right edge).
    Side impacts: `impact_location` of the length from the rear, on the left or right side."""
    spec = test.spec
    reverse = spec.layout == "reverse"
    rear_to_edge, rear_to_centre = vut_geometry(reverse)
    if spec.impact_side != "front":
        along = test.impact_location * VUT["length_m"] - (VUT["length_m"] / 2 - rear_to_centre)
        return along, (VUT["width_m"] / 2) * (1.0 if spec.impact_side == "left" else -1.0)
    across = (test.impact_location - 0.5) * VUT["width_m"]
    return rear_to_edge, -across if reverse else across


def _footprint(test: NcapTest) -> tuple[float, float]:
    """(radius, distance of the footprint centre ahead of the reference point), m, for the face the VUT meets.

    The circle has the target's half width and sits at the part of the target that meets the VUT: against
    the rear face for targets ahead (reference: rear of the rear wheel / back), against the front face where
    the reference is the front of the front wheel (turning and oncoming cyclists and motorcycles) or where a
    crossing target's front hits the VUT's side (CMCscp), else at the box centre (crossing targets; pedestrians
    in turns, whose reference is the hip).
    """
    dummy, spec = test.dummy, test.spec
    radius = dummy.width_m / 2
    if spec.layout in ("longitudinal", "rear"):
        centre, use = radius, "longitudinal"
    elif spec.turn is not None and "turning" in dummy.ref_from_rear_m:
        centre, use = dummy.length_m - radius, "turning"
    elif spec.layout == "crossing" and spec.impact_side != "front":
        centre, use = dummy.length_m - radius, "crossing"
    else:
        centre, use = dummy.length_m / 2, "crossing"
    return radius, centre - dummy.ref_from_rear_m[use]


def _target_line(test: NcapTest) -> tuple[np.ndarray, np.ndarray]:
    """A point on the target's path and its unit direction (world frame)."""
    spec = test.spec
    if spec.layout == "crossing":
        junction_x = LANE_WIDTH_M / 2 if "junction" in spec.tags else 0.0
        if spec.side == "farside":
            return np.array([-junction_x, 0.0]), np.array([0.0, -1.0])
        return np.array([junction_x, 0.0]), np.array([0.0, 1.0])
    if spec.turn is not None:
        y = spec.target_line_m if spec.turn == "farside" else -spec.target_line_m
        forward = spec.moves_with_vut and spec.layout == "turning"
        return np.array([0.0, y]), np.array([1.0 if forward else -1.0, 0.0])
    if spec.layout == "reverse":  # crossing the rear path from the body's right (the VUT faces +x)
        return np.array([0.0, 0.0]), np.array([0.0, 1.0])
    return np.array([0.0, 0.0]), np.array([1.0, 0.0])  # longitudinal, rear: ahead, same direction


def _target_travel(test: NcapTest) -> str:
    """How the target moves: "rest" (triggered, accelerates, then steady), "flying" (steady from t = 0),
    "still" (stationary) or "braking" (ahead at the VUT's speed, then brakes)."""
    spec = test.spec
    if spec.layout == "rear":
        return "braking" if spec.headway_s > 0 else "still"
    if test.target_speed_mps == 0.0:
        return "still"
    if spec.layout == "oncoming" or spec.side == "oncoming" or "flying" in spec.tags:
        return "flying"
    return "rest"


def _time_to_impact_from_rest(distance_m: float, accel_m: float, speed_mps: float) -> float:
    """Time to cover `distance_m` from rest: uniform acceleration over `accel_m`, then constant speed, s."""
    if accel_m <= 0:
        return distance_m / speed_mps
    return 2 * accel_m / speed_mps + (distance_m - accel_m) / speed_mps


@dataclass(frozen=True)
class _Contact:
    """The designed first contact: the reference point then (world), its place in the simulated VUT frame, and
    where the VUT is: straight roads by `reach_m`, turns by (route distance from the turn start, turn start x)."""

    impact: np.ndarray
    local_x_m: float
    local_y_m: float
    reach_m: float = 0.0
    """Straight roads: the target path lies this far ahead of the rear axle (along the travel) at contact, m."""
    turn: tuple[float, float] | None = None


def build_test(test: NcapTest, planner: str = "fsm", v2x: bool = False) -> BuiltTest:
    """The executable Scenario of one catalogue test, and its nominal impact (at first contact). LSC26 tests whose
    VUT starts from rest, creeps or stands parked are built by `ncap/build_low_speed.py`."""
    if test.spec.layout in LOW_SPEED_LAYOUTS and test.spec.turn is None:
        return build_low_speed(test, planner, v2x)
    spec = test.spec
    v = test.cell.vut_speed_kph * KPH
    along, left = _vut_point(test)
    kind = _target_travel(test)
    point, direction = _target_line(test)
    if kind == "still" and spec.layout == "reverse":  # standing with its back to the VUT's path side: facing -y
        direction = np.array([0.0, -1.0])
    radius, centre_ahead = _footprint(test)
    contact = _first_contact(test, _geometry(test, along, left, radius, centre_ahead), point, direction)
    impact = contact.impact
    start, target_time = _start_from_rest(test, impact, direction) if kind == "rest" else (impact, 0.0)
    if contact.turn is not None and spec.layout == "standstill_start":  # LSC26 CMFtap SfS: stopped in the turn
        ego, impact_time = stopped_in_turn_ego(test, contact.turn[0])
        station = 0.0
    else:
        ego, station = _vut(test, v, max(LEAD_TIME_S, target_time + 0.5), contact)
        impact_time = station / v
    vru: dict[str, Any] = {"type": test.dummy.vru_type.value, "radius_m": radius, "speed_time_constant_s": 0.0}
    v_target = test.target_speed_mps
    steady_from = 0.0
    if kind == "rest":
        trigger_m = station - v * target_time
        if trigger_m < 0.0:
            raise ValueError(f"{test.test_id}: the VUT starts too late to synchronise the target")
        accel_m = spec.accel_distance_m
        vru.update(
            top_speed_mps=v_target,
            max_accel_mps2=v_target * v_target / (2 * accel_m) if accel_m > 0 else INSTANT_ACCEL_MPS2,
            trigger={"ego_route_m": trigger_m},
        )
        steady_from = impact_time - target_time + 2 * accel_m / v_target
    elif kind == "flying":
        start = impact - direction * v_target * impact_time
        vru.update(top_speed_mps=v_target, initial_speed_mps=v_target, trigger={"at_time_s": 0.0})
    elif kind == "still":
        vru.update(top_speed_mps=0.0)
    else:
        start, impact, impact_time = _braking_lead(test, v, station, left, vru)
        ego["route"]["length_m"] = float(impact[0] - (point[0] - station)) + EXIT_LENGTH_M
    centre = start + direction * centre_ahead
    heading = math.atan2(direction[1], direction[0])
    vru.update(start={"x_m": float(centre[0]), "y_m": float(centre[1])}, heading_deg=math.degrees(heading))
    scenario = Scenario.model_validate(_scenario_mapping(test, planner, v2x, ego, vru, impact, impact_time))
    nominal = Nominal(
        float(impact[0]), float(impact[1]), impact_time, contact.local_x_m, contact.local_y_m, centre_ahead,
        heading, steady_from,
    )  # fmt: skip
    return BuiltTest(test, scenario, nominal)


def _geometry(test: NcapTest, along: float, left: float, radius: float, centre_ahead: float) -> dict:
    """The contact geometry of a test for `ncap.first_contact` (simulated VUT frame, m)."""
    return {
        "along_m": along,
        "left_m": left,
        "rear_to_centre_m": vut_geometry(test.spec.layout == "reverse")[1],
        "half_length_m": VUT["length_m"] / 2,
        "half_width_m": VUT["width_m"] / 2,
        "centre_ahead_m": centre_ahead,
        "radius_m": radius,
    }


def _first_contact(test: NcapTest, geometry: dict, point: np.ndarray, direction: np.ndarray) -> _Contact:
    """Where the target's reference point is when, without a VUT reaction, the VUT rectangle first touches the
    target's contact circle: on the VUT's nominal lateral line (front and rear impacts) or, for side impacts,
    where the circle first touches the VUT whose nominal side point is on the target path."""
    spec = test.spec
    if spec.turn is not None:
        return _turn_probe(test, geometry, point, direction)
    travel = -1.0 if spec.layout == "reverse" else 1.0  # the left of a VUT travelling -x is -y
    along, left, to_centre = geometry["along_m"], geometry["left_m"], geometry["rear_to_centre_m"]
    nominal = np.array([point[0], LANE_Y_M + travel * left])
    if spec.impact_side != "front":  # the nominal side point on the target path; the circle comes along it
        axle = nominal - np.array([travel * along, travel * left])
        shift = np.arange(0.0, 20.0 + SAMPLE_SPACING_M / 2, SAMPLE_SPACING_M) - 10.0  # the axle at station 10 m
        line = np.column_stack([axle[0] + travel * shift, np.full_like(shift, axle[1]), np.full_like(shift, travel)])
        line = np.column_stack([line, np.zeros((len(shift), 2))])
        station, impact, local = side_first_contact_at(line, 10.0, geometry, nominal, direction)
        return _Contact(impact, float(local[0]), float(local[1]), along + 10.0 - station)
    gap = straight_gap_m(left, travel * direction, geometry["radius_m"], geometry["centre_ahead_m"])
    return _Contact(nominal, along + gap - to_centre, left, along + gap)


def straight_gap_m(left_m: float, direction: np.ndarray, radius_m: float, centre_ahead_m: float) -> float:
    """How far ahead of a straight-driving VUT's leading edge the target's reference point is at first contact,
    m, with the reference point on the VUT's nominal lateral line `left_m` (closed form; `direction`: the
    target's heading in the VUT frame). Contact on the flat face: the circle touches when its centre is one
    radius ahead of the edge (as the virtual box would); beyond the edge's end it touches the corner."""
    centre_left = left_m + centre_ahead_m * direction[1]
    beyond = max(abs(centre_left) - VUT["width_m"] / 2, 0.0)
    if beyond >= radius_m:
        raise ValueError("the target's contact circle passes beside the VUT")
    return math.sqrt(radius_m**2 - beyond**2) - centre_ahead_m * direction[0]


def _start_from_rest(test: NcapTest, impact: np.ndarray, direction: np.ndarray) -> tuple[np.ndarray, float]:
    """Start of the reference point of a target starting from rest, and its time to the impact, s.

    Crossing targets reach their steady speed `lateral_offset_m - accel_distance_m` before the impact point
    (FC26 §3.2.3 figures, V23 `TargetDistanceSteadyState`): the steady stretch is counted back from the impact,
    so the start moves with the impact location."""
    spec = test.spec
    if spec.layout == "crossing":
        start = impact - direction * spec.lateral_offset_m
    elif spec.layout == "longitudinal":
        start = impact - direction * (spec.accel_distance_m + spec.steady_distance_m)
    else:
        start = impact - direction * spec.start_to_impact_m
    distance = float(np.hypot(*(impact - start)))
    return start, _time_to_impact_from_rest(distance, spec.accel_distance_m, test.target_speed_mps)


def _vut(test: NcapTest, v: float, lead_time_s: float, contact: _Contact) -> tuple[dict, float]:
    """The VUT mapping, started `lead_time_s` (at its test speed) before the first contact, and the rear-axle
    route distance at the first contact (m). Reversing tests start with the rear axle REVERSE_START_M before
    the collision point (V23)."""
    spec = test.spec
    reverse = spec.layout == "reverse"
    rear_to_centre = vut_geometry(reverse)[1]
    if contact.turn is not None:
        station_from_turn, turn_start_x = contact.turn
        approach = max(v * lead_time_s - station_from_turn, 5.0)
        start_x = turn_start_x - approach + rear_to_centre
        route = _turn_route(test, approach, EXIT_LENGTH_M)
        station = approach + station_from_turn
    else:
        # reversing: the simulated rear axle is the real front axle, a wheelbase behind the real rear axle
        station = REVERSE_START_M + VUT["wheelbase_m"] - contact.reach_m if reverse else max(v * lead_time_s, 5.0)
        travel = -1.0 if reverse else 1.0
        start_x = _target_line(test)[0][0] - travel * (station + contact.reach_m - rear_to_centre)
        route = {"kind": "straight", "length_m": station + EXIT_LENGTH_M}
    ego = {**VUT, "start": {"x_m": start_x, "y_m": LANE_Y_M, "heading_deg": 0.0}, "cruise_speed_mps": v}
    ego["route"] = route
    if reverse:
        ego["reverse"] = True
    return ego, station


def turn_path_kph(test: NcapTest) -> float:
    """The speed whose protocol path a turning VUT follows, km/h: its test speed, or the LSC26 SfS path."""
    return SFS_TURN_PATH_KPH if test.spec.layout == "standstill_start" else test.cell.vut_speed_kph


def _turn_route(test: NcapTest, approach_m: float, after_m: float) -> dict:
    """Route mapping of a turning test: `approach_m` straight, the protocol turn, `after_m` straight."""
    return ncap_turn_route(test.spec.turn, turn_path_kph(test), approach_m, after_m).model_dump()


def _braking_lead(
    test: NcapTest, v: float, station: float, left: float, vru: dict
) -> tuple[np.ndarray, np.ndarray, float]:
    """CMRb: the motorcycle drives ahead at the VUT's speed with the headway, brakes BRAKE_AFTER_S into the
    run and meets the non-reacting VUT; returns (start, impact point, impact time) and sets its profile."""
    spec = test.spec
    decel = spec.target_decel_mps2
    front_x0 = _target_line(test)[0][0] - station
    gap = v * spec.headway_s
    start = np.array([front_x0 + gap, LANE_Y_M + left])
    stop_s = v / decel
    if 0.5 * decel * stop_s**2 >= gap:  # caught while still braking: gap = a·τ²/2
        closing_s = math.sqrt(2 * gap / decel)
    else:  # the motorcycle stops first; the VUT closes the rest at its speed
        closing_s = stop_s + (gap - 0.5 * decel * stop_s**2) / v
    impact_time = BRAKE_AFTER_S + closing_s
    travelled = v * BRAKE_AFTER_S + v * min(closing_s, stop_s) - 0.5 * decel * min(closing_s, stop_s) ** 2
    vru.update(
        top_speed_mps=v,
        initial_speed_mps=v,
        trigger={"at_time_s": 0.0},
        brake={"after_trigger_s": BRAKE_AFTER_S, "decel_mps2": decel},
    )
    return start, start + np.array([travelled, 0.0]), impact_time


def _scenario_mapping(
    test: NcapTest, planner: str, v2x: bool, ego: dict, vru: dict, impact: np.ndarray, impact_time: float
) -> dict:
    """The Scenario mapping around the VUT and the target: road, sensor, roadside unit, obstructions, timing."""
    spec = test.spec
    junction = "junction" in spec.tags or spec.turn is not None
    mapping = {
        "name": test.test_id,
        "description": f"Euro NCAP {spec.code}: {spec.description}",
        "road": {"layout": "intersection" if junction else "straight", "lane_width_m": LANE_WIDTH_M},
        "ego": ego,
        "sensor": {"range_m": SENSOR_RANGE_M, "fov_deg": SENSOR_FOV_DEG, "lighting": test.lighting},
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
    if spec.obstruction:
        mapping["obstacles"] = obstruction_cars(spec.obstruction, _target_line(test)[0], test.dummy)
    return mapping


def _turn_probe(test: NcapTest, geometry: dict, point: np.ndarray, direction: np.ndarray) -> _Contact:
    """Place the turn so the rear axle leaves it on the centre line of the right lane of the road turned into,
    and find the first contact on it (`ncap.first_contact`)."""
    rear_to_centre = geometry["rear_to_centre_m"]
    samples, turn_start_x = placed_turn(test.spec.turn, turn_path_kph(test))
    along, left = geometry["along_m"], geometry["left_m"]
    if test.spec.impact_side == "front":
        station, impact, ahead = front_first_contact(samples, geometry, point, direction)
        return _Contact(impact, along + ahead - rear_to_centre, left, turn=(station, turn_start_x))
    station, crossing = route_crossing(samples, along, left, point, direction)
    station, impact, local = side_first_contact_at(samples, station, geometry, crossing, direction)
    return _Contact(impact, float(local[0]), float(local[1]), turn=(station, turn_start_x))


def obstruction_cars(kind: str, path_point: np.ndarray, dummy: Dummy) -> list[dict]:
    """Parked obstruction vehicles of a scenario family as Scenario `obstacles` mappings (docs/euroncap.md).

    `path_point` is a point of the target's path (which runs along y); `dummy` sets the path's edge.
    """
    row = OBSTRUCTIONS[kind]
    half_target = dummy.width_m / 2
    cars = []
    if row.along_vut:  # parallel to the VUT path, nearside; the first car's front before the path edge
        y = LANE_Y_M - (VUT["width_m"] / 2 + row.clearance_m)
        front = path_point[0] - half_target - row.first_offset_m
        for name in row.cars:
            length, width = OBSTRUCTION_CARS[name]
            centre = {"x_m": front - length / 2, "y_m": y - width / 2, "heading_deg": 0.0}
            cars.append({"kind": name, "centre": centre, "length_m": length, "width_m": width})
            front -= length + row.gap_m
        return cars
    outward = 1.0 if path_point[0] < 0 else -1.0  # farside arm (path at x < 0): y > 0; nearside arm: y < 0
    end = LANE_Y_M + outward * row.first_offset_m
    for name in row.cars:  # on the VUT's side (-x) of the target's path, parallel to the side road
        length, width = OBSTRUCTION_CARS[name]
        x = path_point[0] - (half_target + row.clearance_m + width / 2)
        centre = {"x_m": x, "y_m": end + outward * length / 2, "heading_deg": 90.0}
        cars.append({"kind": name, "centre": centre, "length_m": length, "width_m": width})
        end += outward * (length + row.gap_m)
    return cars
