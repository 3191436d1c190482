"""Build the LSC26 low-speed tests (VUT starting from standstill, pedal misapplication, dooring) as Scenarios.

Spec: docs/low_speed_situations.md. World frame as in `ncap.build`: the VUT faces +x in the lane at
y = LANE_Y_M; the target's path crosses x = 0 (the SfS side impact: x = -lane/2, the junction's farside lane).
Synchronisation is closed form: the VUT is held at rest until T0 (a multiple of the time step, where the
engine starts the phase), then accelerates at a constant rate; the target (at its test speed from t = 0) is
placed so that its reference point (the circle centre) is at the nominal impact location at the first contact
with the `none` planner (the engine interpolates the contact time within the step). The start-off time comes
from a probe run of the VUT alone (`start_off_probe_s`): it includes the actuator lag and jerk limit.
"""

from __future__ import annotations

import math
from typing import Any

from vrusim.ncap.editions.lsc26 import (
    CBDA_DOOR_OPERATION_M,
    CBDA_PATH_CLEARANCE_M,
    CBNAO_SFS_OBSTRUCTION,
    CMCSCP_SFS_START_M,
    CPMFC_TACC_TO_TARGET_M,
    CPMRCM_TARGET_START_M,
)
from vrusim.ncap.probes import travel_probe_s
from vrusim.ncap.protocol import KPH, LANE_WIDTH_M, OBSTRUCTION_CARS
from vrusim.ncap.test_case import SENSOR_FOV_DEG, SENSOR_RANGE_M, VUT, BuiltTest, NcapTest, Nominal
from vrusim.scenario.schema import Scenario

LOW_SPEED_LAYOUTS = ("standstill_start", "pedal_misapplication", "dooring")
"""Layouts `build_low_speed` builds (`ncap.build.build_test` dispatches them here)."""

DT_S = 0.01
"""Simulation step, s (the phase start T0 is a multiple of it)."""
LANE_Y_M = -LANE_WIDTH_M / 2
GO_ACCEL_MPS2 = 1.5
"""Stand-in for the TB CA 102 accelerator-pedal profile (not in LSC26): constant rate, m/s² (UNVERIFIED)."""
GO_SPEED_MPS = 10.0 * KPH
"""... up to this speed, m/s (UNVERIFIED)."""
LEAD_S = 4.5
"""Nominal impact at least this long after t = 0: the target is steady from TTC 4 s (LSC26 §3.2.1.1) + 0.5 s."""
TAIL_S = 4.0
"""Simulated time after the nominal impact, s."""
DOW_SENSOR = {"range_m": 30.0, "fov_deg": 360.0}
"""CBDA: the front-bumper sector with 360° stands in for rear-corner radars (UNVERIFIED, spec 'CBDA')."""
CREEP_SPEED_MPS, CREEP_ACCEL_MPS2 = 1.5, 1.0
"""CPMFC: the VUT's Maximum Creeping Speed and idle rate (vehicle data; our VUT's, UNVERIFIED)."""
FULL_ACCEL_MPS2, FULL_SPEED_MPS = 4.0, 5.0
"""CPMFC: VUT response to the full accelerator input (LSC26 defines the pedal only; UNVERIFIED)."""
CPMFC_CREEP_AFTER_S = 1.0
"""LSC26 §3.2.2.3 d2: 'after creeping for [1]s' (read: 1 s at the creep speed after d1, UNVERIFIED)."""
OBSTRUCTION_CAR = "small car"
"""CBNAO SfS full obstruction and CBDA obstruction car (LSC26 App. A.1 smaller obstruction 4.1-4.4 × 1.7-1.9 m)."""
DOOR: dict[str, float] = {"hinge_from_front_m": 1.3, "length_m": 1.1, "max_angle_deg": 60.0,
                          "opening_rate_deg_ps": 60.0}  # fmt: skip
"""CBDA driver's door of our VUT; kinematics not in LSC26 (UNVERIFIED, docs/low_speed_situations.md)."""
CBDA_LEAD_S = 3.0
"""CBDA: the cyclist rides this long before the door operation, s."""


def start_off_time_s(distance_m: float, accel_mps2: float = GO_ACCEL_MPS2, speed_mps: float = GO_SPEED_MPS) -> float:
    """Time to travel `distance_m` from rest at `accel_mps2` up to `speed_mps`, then steady, s."""
    ramp_m = speed_mps**2 / (2 * accel_mps2)
    if distance_m <= ramp_m:
        return math.sqrt(2 * distance_m / accel_mps2)
    return speed_mps / accel_mps2 + (distance_m - ramp_m) / speed_mps


def start_off_probe_s(ego: dict, travel_m: float) -> float:
    """Time from the start-off (phase at t = 0) until the ego has travelled `travel_m`, s: the engine's own
    longitudinal dynamics (driver request, actuator lag, jerk limit); the closed form `start_off_time_s`
    ignores the lag (about 0.09 s late)."""
    duration_s = math.ceil(start_off_time_s(travel_m) + 2.0)  # whole seconds: probes of similar tests are shared
    return travel_probe_s({**ego, "driver": start_off_driver(0.0)}, travel_m, duration_s)


def first_step_at_s(t_s: float) -> float:
    """The first step time at or after `t_s` (≥ 0), s."""
    return max(math.ceil(t_s / DT_S - 1e-9), 0) * DT_S


def build_low_speed(test: NcapTest, planner: str, v2x: bool) -> BuiltTest:
    """The executable Scenario of an LSC26 standstill-start, pedal-misapplication or dooring test."""
    spec = test.spec
    if spec.layout == "dooring":
        return _dooring(test, planner, v2x)
    if spec.layout == "pedal_misapplication":
        return _pedal_misapplication(test, planner, v2x)
    if spec.layout != "standstill_start":
        raise ValueError(f"{test.test_id}: layout {spec.layout!r} is not a low-speed layout {LOW_SPEED_LAYOUTS}")
    if spec.turn is not None:
        raise ValueError(f"{test.test_id}: a standstill start in a turn (CMFtap SfS) is built by ncap.build.build_test")
    if "reverse" in spec.tags:
        return _reversing_start(test, planner, v2x)
    return _crossing_start(test, planner, v2x)


def _ego(centre_x_m: float, cruise_mps: float, route_m: float, driver: dict | None, reverse: bool = False) -> dict:
    """VUT mapping at rest, rectangle centre at (`centre_x_m`, LANE_Y_M), facing +x."""
    ego: dict[str, Any] = {**VUT, "start": {"x_m": centre_x_m, "y_m": LANE_Y_M, "heading_deg": 0.0}}
    ego.update(cruise_speed_mps=cruise_mps, initial_speed_mps=0.0, route={"kind": "straight", "length_m": route_m})
    if driver is not None:
        ego["driver"] = driver
    if reverse:
        ego["reverse"] = True
    return ego


def start_off_driver(t0_s: float) -> dict:
    """Driver held at rest by the brake until `t0_s`, then the CA 102 stand-in."""
    return {"phases": [{"at_time_s": t0_s, "target_speed_mps": GO_SPEED_MPS, "accel_mps2": GO_ACCEL_MPS2}]}


def _vru(test: NcapTest, x_m: float, y_m: float, heading_deg: float, speed_mps: float) -> dict:
    """Target circle (the dummy's half width) centred on its reference point, at `speed_mps` from t = 0."""
    vru = {"type": test.dummy.vru_type.value, "radius_m": test.dummy.width_m / 2, "speed_time_constant_s": 0.0}
    vru.update(start={"x_m": x_m, "y_m": y_m}, heading_deg=heading_deg, top_speed_mps=speed_mps)
    if speed_mps > 0:
        vru.update(initial_speed_mps=speed_mps, trigger={"at_time_s": 0.0})
    return vru


def _crossing_start(test: NcapTest, planner: str, v2x: bool) -> BuiltTest:
    """CBNAO SfS (front impact, cyclist from the nearside, LSC26 §3.2.1.1) and CMCscp SfS (side impact, EMT
    from the farside, §3.1.2)."""
    spec, length, width = test.spec, VUT["length_m"], VUT["width_m"]
    radius, v_t = test.dummy.width_m / 2, test.target_speed_mps
    side_impact = spec.impact_side != "front"
    if side_impact:  # the VUT's impact point (fraction of the length) travels 2.9 m (§3.1.2, reading UNVERIFIED)
        line_x = -LANE_WIDTH_M / 2
        ahead = (test.impact_location - 0.5) * length  # impact point ahead of the rectangle centre
        travel = CMCSCP_SFS_START_M
        centre0 = line_x - travel - ahead
        local_y = width / 2 if spec.impact_side == "left" else -width / 2
        hit_y = LANE_Y_M + local_y + math.copysign(radius, local_y)
    else:  # the front is d before the reference point's path; contact when the gap is the target's radius
        line_x, ahead = 0.0, length / 2
        gap = test.cell.gap_m if test.cell.gap_m is not None else 0.0
        travel = gap - radius
        centre0 = line_x - gap - ahead
        local_y = (test.impact_location - 0.5) * width
        hit_y = LANE_Y_M + local_y
    ego = _ego(centre0, GO_SPEED_MPS, travel + ahead + length + 10.0, None)
    t_go = start_off_probe_s(ego, travel)
    t0 = first_step_at_s(max(LEAD_S - t_go, 1.0))
    ego["driver"] = start_off_driver(t0)
    t_contact = t0 + t_go
    direction = -1.0 if spec.side == "farside" else 1.0  # farside: from +y moving -y
    start_y = hit_y - direction * v_t * t_contact
    vru = _vru(test, line_x, start_y, 90.0 * direction, v_t)
    obstacles = _sfs_obstruction(line_x, centre0 + length / 2) if spec.code.startswith("CBNAO") else []
    impact = (line_x, hit_y)
    scenario = _scenario(test, planner, v2x, ego, [vru], obstacles, t_contact, junction="junction" in spec.tags)
    heading = math.radians(90.0 * direction)
    nominal = Nominal(impact[0], impact[1], t_contact, ahead, local_y, 0.0, heading, 0.0)
    return BuiltTest(test, scenario, nominal)


def _sfs_obstruction(line_x: float, front_x: float) -> list[dict]:
    """CBNAO SfS full obstruction (§3.2.1.1): a parked car 1 m beside the VUT on the nearside, its front
    2.50 m before the cyclist's reference-point path (which edge counts is UNVERIFIED)."""
    length, width = OBSTRUCTION_CARS[OBSTRUCTION_CAR]
    y = LANE_Y_M - VUT["width_m"] / 2 - CBNAO_SFS_OBSTRUCTION["vut_beside_m"] - width / 2
    x = line_x - CBNAO_SFS_OBSTRUCTION["obstruction_to_ebt_ref_m"] - length / 2
    return [{"kind": OBSTRUCTION_CAR, "centre": {"x_m": x, "y_m": y, "heading_deg": 0.0},
             "length_m": length, "width_m": width}]  # fmt: skip


def _reversing_start(test: NcapTest, planner: str, v2x: bool) -> BuiltTest:
    """CPMRCm (§3.2.2.1): reversing from rest; the child walks in from the nearside (the body's right, -y),
    starting CPMRCM_TARGET_START_M from the path centre; the rear gap is the cell's `gap_m`."""
    length, width = VUT["length_m"], VUT["width_m"]
    radius, v_t = test.dummy.width_m / 2, test.target_speed_mps
    gap = test.cell.gap_m if test.cell.gap_m is not None else 0.0
    travel = gap - radius  # rear edge (x = centre - L/2, moving -x) to contact
    centre0 = gap + length / 2
    local_y = (test.impact_location - 0.5) * width  # 0 = the body's right edge (-y)
    hit_y = LANE_Y_M + local_y
    ego = _ego(centre0, GO_SPEED_MPS, travel + length + 10.0, None, reverse=True)
    t_go = start_off_probe_s(ego, travel)
    to_hit_m = CPMRCM_TARGET_START_M + local_y
    t0 = first_step_at_s(to_hit_m / v_t - t_go)  # the child starts at least 10 m out (+ < v dt)
    t_contact = t0 + t_go
    vru = _vru(test, 0.0, hit_y - v_t * t_contact, 90.0, v_t)
    ego["driver"] = start_off_driver(t0)
    scenario = _scenario(test, planner, v2x, ego, [vru], [], t_contact)
    # simulated (mirrored) frame: the leading edge is L/2 ahead, the body's left is the simulated right
    nominal = Nominal(0.0, hit_y, t_contact, length / 2, -local_y, 0.0, math.pi / 2, 0.0)
    return BuiltTest(test, scenario, nominal)


def cpmfc_distance_m(row: str) -> float:
    """CPMFC d of grid row "d1" / "d2" (§3.2.2.3): d1 = creeping distance until the creep speed; d2 = d1 +
    CPMFC_CREEP_AFTER_S at it."""
    if row not in ("d1", "d2"):
        raise ValueError(f"CPMFC grid row: expected d1 or d2, got {row!r}")
    d1 = CREEP_SPEED_MPS**2 / (2 * CREEP_ACCEL_MPS2)
    return d1 + (CREEP_SPEED_MPS * CPMFC_CREEP_AFTER_S if row == "d2" else 0.0)


def _pedal_misapplication(test: NcapTest, planner: str, v2x: bool) -> BuiltTest:
    """CPMFC (§3.2.2.3): creeping from rest, full accelerator (T_ACC) after d; the stationary child's reference
    point 1.5 m (nominal of 1.5 + [0.5]) ahead of the front at T_ACC."""
    length, width = VUT["length_m"], VUT["width_m"]
    radius = test.dummy.width_m / 2
    d = cpmfc_distance_m(test.cell.row_label)
    child_x = length / 2 + d + CPMFC_TACC_TO_TARGET_M[0]  # VUT centre starts at x = 0
    local_y = (test.impact_location - 0.5) * width
    driver = {
        "creep_speed_mps": CREEP_SPEED_MPS,
        "creep_accel_mps2": CREEP_ACCEL_MPS2,
        "phases": [
            {"at_time_s": 0.0, "target_speed_mps": CREEP_SPEED_MPS, "accel_mps2": CREEP_ACCEL_MPS2,
             "accelerator": False},
            {"ego_route_m": d, "target_speed_mps": FULL_SPEED_MPS, "accel_mps2": FULL_ACCEL_MPS2},
        ],
    }  # fmt: skip
    ego = _ego(0.0, CREEP_SPEED_MPS, child_x + 10.0, driver)
    t_contact = travel_probe_s(ego, d + CPMFC_TACC_TO_TARGET_M[0] - radius, 10.0)
    vru = _vru(test, child_x, LANE_Y_M + local_y, -90.0, 0.0)
    scenario = _scenario(test, planner, v2x, ego, [vru], [], t_contact)
    nominal = Nominal(child_x - radius, LANE_Y_M + local_y, t_contact, length / 2, local_y, 0.0, -math.pi / 2, 0.0)
    return BuiltTest(test, scenario, nominal)


def _dooring(test: NcapTest, planner: str, v2x: bool) -> BuiltTest:
    """CBDA (§3.2.3): parked VUT with the driver's door (left), a smaller obstruction car `gap_m` behind it,
    both aligned 1 m from the cyclist's path; the door is operated at the door operation distance."""
    length, width = VUT["length_m"], VUT["width_m"]
    radius, v_t = test.dummy.width_m / 2, test.target_speed_mps
    speed_kph = round(v_t / KPH, 6)
    if speed_kph not in CBDA_DOOR_OPERATION_M:
        raise ValueError(f"{test.test_id}: no CBDA door operation distance at {speed_kph:g} km/h")
    operation_m = CBDA_DOOR_OPERATION_M[speed_kph][0]
    door_rear_x = length / 2 - DOOR["hinge_from_front_m"] - DOOR["length_m"]  # VUT centre at x = 0
    path_y = LANE_Y_M + width / 2 + CBDA_PATH_CLEARANCE_M
    t_operation = CBDA_LEAD_S
    start_x = door_rear_x - operation_m - radius - v_t * t_operation
    vru = _vru(test, start_x, path_y, 0.0, v_t)
    door = {"side": "left", **DOOR, "trigger": {"vru_distance_m": operation_m, "vru": 0}}
    ego = _ego(0.0, 0.0, 10.0, None)
    ego["door"] = door
    car_length, car_width = OBSTRUCTION_CARS[OBSTRUCTION_CAR]
    gap = test.cell.gap_m if test.cell.gap_m is not None else 0.0
    car = {"kind": OBSTRUCTION_CAR, "length_m": car_length, "width_m": car_width,
           "centre": {"x_m": -length / 2 - gap - car_length / 2, "y_m": LANE_Y_M + (width - car_width) / 2,
                      "heading_deg": 0.0}}  # fmt: skip
    t_door = t_operation + operation_m / v_t  # the cyclist's front at the rear edge of the closed door
    scenario = _scenario(test, planner, v2x, ego, [vru], [car], t_door, sensor=DOW_SENSOR)
    nominal = Nominal(door_rear_x, path_y, t_door, door_rear_x, width / 2, 0.0, 0.0, 0.0)
    return BuiltTest(test, scenario, nominal)


def _scenario(
    test: NcapTest,
    planner: str,
    v2x: bool,
    ego: dict,
    vrus: list[dict],
    obstacles: list[dict],
    impact_time_s: float,
    junction: bool = False,
    sensor: dict | None = None,
) -> Scenario:
    """The validated Scenario around the VUT and its target (v2x: a roadside unit by the nominal impact)."""
    mapping: dict[str, Any] = {
        "name": test.test_id,
        "description": f"Euro NCAP {test.spec.code}: {test.spec.description}",
        "road": {"layout": "intersection" if junction else "straight", "lane_width_m": LANE_WIDTH_M},
        "ego": ego,
        "sensor": {**(sensor or {"range_m": SENSOR_RANGE_M, "fov_deg": SENSOR_FOV_DEG}), "lighting": test.lighting},
        "v2x": {"enabled": v2x, "rsu": {"x_m": 5.0, "y_m": 5.0}, "comm_range_m": 250.0, "coverage_range_m": 40.0},
        "planner": {"name": planner},
        "vrus": vrus,
        "sim": {"dt_s": DT_S, "duration_s": round(impact_time_s + TAIL_S, 2)},
    }
    if obstacles:
        mapping["obstacles"] = obstacles
    return Scenario.model_validate(mapping)
