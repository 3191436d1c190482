"""OpenSCENARIO entities of a scenario: the ego and parked cars as cars, VRUs as pedestrians or two-wheelers.

Reference points: a car's is the centre of its rear axle on the ground (the OpenSCENARIO convention), so its
bounding box centre lies `x_center` ahead of it. A VRU is a point mass in vrusim: its reference point is its
footprint centre (bounding box centred on it, also for two-wheelers, whose axles sit at ± wheelbase / 2).
A VRU's box is the square around its circular footprint (length = width = 2 radius_m), of its type's height.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from vrusim.extras import extra

with extra("export"):
    from scenariogeneration import xosc

from vrusim.scenario.schema import Ego, Obstacle, Vru
from vrusim.scenario.vru_types import VruType


@dataclass(frozen=True)
class VruLook:
    """How a VRU type appears in OpenSCENARIO: category (None: a Pedestrian), height (m), mass (kg), wheelbase (m)."""

    vehicle_category: str | None
    height_m: float
    mass_kg: float
    wheelbase_m: float = 0.0


VRU_LOOKS: dict[VruType, VruLook] = {
    VruType.PEDESTRIAN: VruLook(None, 1.8, 75.0),
    VruType.CYCLIST: VruLook("bicycle", 1.8, 90.0, 1.1),
    VruType.E_SCOOTER: VruLook("bicycle", 1.8, 95.0, 0.9),  # no e-scooter category in OpenSCENARIO 1.x
    VruType.MOTORCYCLIST: VruLook("motorbike", 1.5, 280.0, 1.5),
}
"""OpenSCENARIO appearance per VRU type (heights, masses, wheelbases: typical values, our choice)."""

CAR_HEIGHT_M = 1.5
CAR_MASS_KG = 1500.0
WHEEL_DIAMETER_M = 0.65
TRACK_FRACTION = 0.85
"""Axle track width as a fraction of the car's width."""
PARKED_REAR_OVERHANG_FRACTION, PARKED_WHEELBASE_FRACTION = 0.2, 0.6
"""A parked car's rear overhang and wheelbase as fractions of its length (not given by the scenario)."""
MAX_SPEED_MPS = 70.0
"""Top speed given to cars (an OpenSCENARIO Performance field; vrusim has none)."""


def ego_box_offset_m(ego: Ego) -> float:
    """Distance of the ego's box centre ahead of its rear axle (the reference point), m."""
    return ego.length_m / 2 - ego.rear_overhang_m


def ego_reference_pose(ego: Ego) -> tuple[float, float, float]:
    """World pose (x m, y m, heading rad) of the ego's reference point: its real rear axle, facing the body."""
    heading = math.radians(ego.start.heading_deg)
    back = ego_box_offset_m(ego)
    return ego.start.x_m - back * math.cos(heading), ego.start.y_m - back * math.sin(heading), heading


def _car(name: str, length_m: float, width_m: float, rear_overhang_m: float, wheelbase_m: float, **limits):
    box = xosc.BoundingBox(width_m, length_m, CAR_HEIGHT_M, length_m / 2 - rear_overhang_m, 0.0, CAR_HEIGHT_M / 2)
    track = TRACK_FRACTION * width_m
    front = xosc.Axle(limits.pop("max_steer_rad"), WHEEL_DIAMETER_M, track, wheelbase_m, WHEEL_DIAMETER_M / 2)
    rear = xosc.Axle(0.0, WHEEL_DIAMETER_M, track, 0.0, WHEEL_DIAMETER_M / 2)
    return xosc.Vehicle(name, xosc.VehicleCategory.car, box, front, rear, MAX_SPEED_MPS, mass=CAR_MASS_KG, **limits)


def ego_vehicle(ego: Ego) -> xosc.Vehicle:
    """The ego as a car: box from length / width / rear overhang, axles from the wheelbase, its accel limits."""
    return _car(
        "ego",
        ego.length_m,
        ego.width_m,
        ego.rear_overhang_m,
        ego.wheelbase_m,
        max_steer_rad=math.radians(ego.max_steer_deg),
        max_acceleration=ego.max_accel_mps2,
        max_deceleration=ego.max_decel_mps2,
    )


def obstacle_reference_pose(obstacle: Obstacle) -> tuple[float, float, float]:
    """World pose (x m, y m, heading rad) of a parked car's rear axle."""
    heading = math.radians(obstacle.centre.heading_deg)
    back = obstacle.length_m * (0.5 - PARKED_REAR_OVERHANG_FRACTION)
    return obstacle.centre.x_m - back * math.cos(heading), obstacle.centre.y_m - back * math.sin(heading), heading


def obstacle_vehicle(obstacle: Obstacle, name: str) -> xosc.Vehicle:
    """A parked car (an obstacle) as a stationary car of its length and width."""
    car = _car(
        name,
        obstacle.length_m,
        obstacle.width_m,
        PARKED_REAR_OVERHANG_FRACTION * obstacle.length_m,
        PARKED_WHEELBASE_FRACTION * obstacle.length_m,
        max_steer_rad=0.5,
        max_acceleration=0.0,
        max_deceleration=10.0,
    )
    car.add_property("vrusim:kind", obstacle.kind)
    return car


def vru_entity(vru: Vru, name: str) -> xosc.Pedestrian | xosc.Vehicle:
    """A VRU as a Pedestrian or a two-wheeled Vehicle, with its footprint's box and its speed limits."""
    look = VRU_LOOKS[vru.type]
    size = 2 * vru.footprint_m
    box = xosc.BoundingBox(size, size, look.height_m, 0.0, 0.0, look.height_m / 2)
    if look.vehicle_category is None:
        entity = xosc.Pedestrian(name, look.mass_kg, xosc.PedestrianCategory.pedestrian, box)
    else:
        wheel = WHEEL_DIAMETER_M
        half_base = look.wheelbase_m / 2
        entity = xosc.Vehicle(
            name,
            getattr(xosc.VehicleCategory, look.vehicle_category),
            box,
            xosc.Axle(0.5, wheel, 0.1, half_base, wheel / 2),
            xosc.Axle(0.0, wheel, 0.1, -half_base, wheel / 2),
            max(vru.speed_mps, vru.initial_speed_mps),
            vru.accel_mps2,
            vru.brake.decel_mps2 if vru.brake is not None else vru.accel_mps2,
            mass=look.mass_kg,
        )
    entity.add_property("vrusim:type", vru.type.value)
    entity.add_property("vrusim:radius_m", repr(vru.footprint_m))
    return entity
