"""Pack many Scenarios into one structure-of-arrays parameter set (first axis = variant, second = VRU slot).

After `pack`, nothing in the engine reads a pydantic model: every component finds its settings here, packed
once (the sensor model's in `sensor`, the V2X channel's in `channel`; a planner validates its own
`planner_params`, plain mappings, at `reset`).
"""

from __future__ import annotations

import copy
import math
from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any, ClassVar

import numpy as np

from vrusim.errors import UserInputError
from vrusim.geometry.path_table import PathTable
from vrusim.geometry.paths import Line, PathSpec
from vrusim.scenario.routes import ego_route_spec, vru_path_spec
from vrusim.scenario.schema import Scenario, Trigger
from vrusim.sim.door import DoorArrays, pack_door
from vrusim.sim.driver import DriverArrays, pack_driver
from vrusim.sim.sensing.occlusion import ObstacleArrays, pack_obstacles
from vrusim.sim.sensing.sensor_params import SensorParams, pack_sensor
from vrusim.sim.v2x.channel_params import ChannelParams, pack_channel
from vrusim.sim.vru import shaped as _shaped  # noqa: F401  (registers the shaped models cubic and sinusoidal)
from vrusim.sim.vru.point_mass import POINT_MASS
from vrusim.sim.vru.registry import vru_motion, vru_motion_entries

TRIGGER_TIME, TRIGGER_DISTANCE, TRIGGER_TIME_TO_ARRIVAL, TRIGGER_ROUTE = 0, 1, 2, 3
TRIGGER_SPEED_BELOW, TRIGGER_SPEED_ABOVE, TRIGGER_STANDSTILL = 4, 5, 6
"""Trigger kinds on the ego's speed at run time (`Trigger.ego_speed_below_mps`, `ego_speed_above_mps`,
`ego_standstill_s`)."""
_SPEED_TRIGGERS = (
    ("ego_speed_below_mps", TRIGGER_SPEED_BELOW),
    ("ego_speed_above_mps", TRIGGER_SPEED_ABOVE),
    ("ego_standstill_s", TRIGGER_STANDSTILL),
)
_PARKED_SLOT = PathSpec(1e7, 1e7, 0.0, (Line(1.0),))
"""Path of an unused VRU slot: 10,000 km away, so it never interacts."""


@dataclass(frozen=True)
class BatchParams:
    """Constant per-variant parameters of a batch. Shapes: [B] or [B, K] (lists: one item per variant); SI units."""

    shared: ClassVar[frozenset[str]] = frozenset({"routes", "vru_paths"})
    """Path tables shared by all variants (each addresses its rows by offset): kept whole by `take`."""

    names: list[str]
    """Each variant's scenario name."""
    planner_names: list[str]
    """Each variant's `planner.name`."""
    planner_params: list[Mapping[str, Any]]
    """Each variant's `planner.params` as written (read-only mappings); the planner validates them at `reset`."""
    score_profiles: list[str]
    """Each variant's score profile name (`metrics.profile`)."""
    score_overrides: list[dict[str, float]]
    """Each variant's safety thresholds that replace its profile's (`metrics.safety_*_threshold_*`)."""
    injury_risk_curves: list[str]
    """Each variant's fatality risk curve (`metrics.injury_risk_curve`)."""
    vru_motion: str
    """The VRU motion model every VRU of the batch moves by (`vrus[k].motion`, `vrusim.sim.vru.registry`)."""
    dt_s: float
    n_steps: int
    duration_s: np.ndarray
    seed: np.ndarray
    """Each variant's `sim.seed` (int64): the key of its random numbers (`vrusim.sim.rng`)."""
    stop_on_collision: np.ndarray
    stop_at_route_end: np.ndarray
    # ego
    half_length_m: np.ndarray
    half_width_m: np.ndarray
    wheelbase_m: np.ndarray
    rear_to_centre_m: np.ndarray
    rear_to_front_m: np.ndarray
    cruise_speed_mps: np.ndarray
    start_speed_mps: np.ndarray
    max_accel_mps2: np.ndarray
    max_decel_mps2: np.ndarray
    max_jerk_mps3: np.ndarray
    lag_s: np.ndarray
    max_curvature_per_m: np.ndarray
    lateral_gain: np.ndarray
    heading_gain: np.ndarray
    routes: PathTable
    route_offset: np.ndarray
    route_length_m: np.ndarray
    reverse: np.ndarray
    """The ego reverses (`ego.reverse`, bool): its simulated frame is the real body mirrored front to back."""
    driver: DriverArrays
    """The driver's pedal schedules (`ego.driver`, `sim/driver.py`)."""
    door: DoorArrays
    """The opening doors (`ego.door`, `sim/door.py`)."""
    # sensor
    sensor_enabled: np.ndarray
    sensor_range_m: np.ndarray
    sensor_cos_half: np.ndarray
    sensor_sin_half: np.ndarray
    obstacles: ObstacleArrays  # count [B]; boxes [B, M], M = most obstacles in the batch; occlude the sensor only
    sensor: SensorParams
    """The sensor model's settings (latency, frame period, misses, noise)."""
    # v2x
    v2x_enabled: np.ndarray
    rsu_x_m: np.ndarray
    rsu_y_m: np.ndarray
    comm_range_m: np.ndarray
    coverage_range_m: np.ndarray
    channel: ChannelParams
    """The V2X channel's settings (generation, delay, loss, outages)."""
    # vrus [B, K]
    vru_valid: np.ndarray
    vru_type: np.ndarray
    vru_top_speed_mps: np.ndarray
    vru_max_accel_mps2: np.ndarray
    vru_radius_m: np.ndarray
    vru_tau_s: np.ndarray
    vru_initial_speed_mps: np.ndarray
    vru_brake_after_s: np.ndarray
    """Delay from trigger to braking, s (inf: never brakes)."""
    vru_brake_decel_mps2: np.ndarray
    vru_paths: PathTable
    vru_path_offset: np.ndarray
    trigger_kind: np.ndarray
    trigger_value: np.ndarray
    trigger_x_m: np.ndarray
    trigger_y_m: np.ndarray
    # surrogate and injury metrics (docs/metrics.md)
    ego_mass_kg: np.ndarray
    """`ego.mass_kg` [B]."""
    vru_mass_kg: np.ndarray
    """Each VRU's mass with its vehicle [B, K] (`vrus[k].mass_kg` or its type's default); 1 in empty slots."""
    tet_ttc_threshold_s: np.ndarray
    """TTC threshold of TET / TIT [B] (`metrics.tet_ttc_threshold_s`), s."""

    @property
    def size(self) -> int:
        """Number of variants B."""
        return self.duration_s.shape[0]

    @property
    def vru_slots(self) -> int:
        """Number of VRU slots K (the largest VRU count in the batch)."""
        return self.vru_valid.shape[1]


_NO_PARAMETERS: Mapping[str, Any] = MappingProxyType({})


_SCALARS = (bool, int, float, str, type(None))


def _read_only(given: Mapping[str, Any]) -> Mapping[str, Any]:
    """A read-only copy of a scenario's `planner.params` (nested lists and mappings copied too)."""
    if not given:
        return _NO_PARAMETERS
    flat = all(isinstance(value, _SCALARS) for value in given.values())
    return MappingProxyType(dict(given) if flat else copy.deepcopy(dict(given)))


_SCALAR_NAMES = (
    "fov_deg", "max_steer_deg", "wheelbase_m", "duration_s", "half_length_m", "half_width_m", "rear_to_centre_m",
    "rear_to_front_m", "cruise_speed_mps", "start_speed_mps", "max_accel_mps2", "max_decel_mps2", "max_jerk_mps3",
    "lag_s", "lateral_gain", "heading_gain", "route_length_m", "sensor_range_m", "rsu_x_m", "rsu_y_m",
    "comm_range_m", "coverage_range_m",
)  # fmt: skip


def _scalars(s: Scenario) -> tuple[float, ...]:
    """One scenario's scalar settings, in `_SCALAR_NAMES` order (SI units; degrees where named)."""
    ego, sensor, v2x = s.ego, s.sensor, s.v2x
    rsu = v2x.rsu
    return (
        sensor.fov_deg,
        ego.max_steer_deg,
        ego.wheelbase_m,
        s.sim.duration_s,
        ego.length_m / 2,
        ego.width_m / 2,
        # a reversing ego is packed mirrored front to back: its "rear" axle and overhang trail in the motion
        ego.length_m / 2 - ego.trailing_overhang_m,
        ego.length_m - ego.trailing_overhang_m,
        ego.cruise_speed_mps,
        ego.start_speed_mps,
        ego.max_accel_mps2,
        ego.max_decel_mps2,
        ego.max_jerk_mps3 or math.inf,
        ego.actuator_lag_s,
        ego.tracking.lateral_gain_per_m2,
        ego.tracking.heading_gain_per_m,
        ego.route.length_m,
        sensor.effective_range_m,
        rsu.x_m if rsu else 0.0,
        rsu.y_m if rsu else 0.0,
        v2x.comm_range_m,
        v2x.coverage_range_m,
    )


def _scalar_columns(scenarios: list[Scenario]) -> dict[str, np.ndarray]:
    """`_scalars` of every scenario as float columns [B] (each its own C-contiguous array), read in one pass."""
    table = np.array([_scalars(s) for s in scenarios], dtype=float).reshape(len(scenarios), len(_SCALAR_NAMES))
    return {name: np.ascontiguousarray(table[:, j]) for j, name in enumerate(_SCALAR_NAMES)}


def _batch_motion(scenarios: list[Scenario]) -> str:
    """The one VRU motion model of a batch (`point_mass` without VRUs); an unknown model, or several in one batch,
    is a UserInputError naming the field."""
    used: dict[str, str] = {}
    for scenario in scenarios:
        for k, vru in enumerate(scenario.vrus):
            used.setdefault(vru.motion, f"{scenario.name}: vrus[{k}].motion")
    known = vru_motion_entries()
    for name, where in used.items():
        if name not in known:
            raise UserInputError(f"{where}: unknown VRU motion model {name!r}; expected one of: {', '.join(known)}")
    if len(used) > 1:
        raise UserInputError(
            f"vrus[].motion: one batch moves all its VRUs by one motion model, got {', '.join(sorted(used))}; "
            "run them as separate batches"
        )
    return next(iter(used), POINT_MASS)


def _speed_trigger(trigger: Trigger) -> tuple[int, float]:
    """(kind, value) of a trigger on the ego's speed."""
    for name, kind in _SPEED_TRIGGERS:
        value = getattr(trigger, name)
        if value is not None:
            return kind, value
    raise AssertionError("a validated Trigger sets one condition")


def _unique_rows(specs: list) -> tuple[list, np.ndarray]:
    rows: dict = {}
    index = np.array([rows.setdefault(spec, len(rows)) for spec in specs], dtype=np.int64)
    return list(rows), index


def pack(scenarios: list[Scenario]) -> BatchParams:
    """Pack scenarios (all with the same dt) into arrays for the batch engine."""
    if not scenarios:
        raise UserInputError("a batch needs at least one scenario")
    dt = scenarios[0].sim.dt_s
    if any(s.sim.dt_s != dt for s in scenarios):
        raise UserInputError("sim.dt_s: every scenario of one batch must use the same time step")
    B = len(scenarios)
    K = max(len(s.vrus) for s in scenarios)

    scalars = _scalar_columns(scenarios)

    route_specs, route_rows = _unique_rows([ego_route_spec(s.ego) for s in scenarios])
    routes = PathTable(route_specs, what="ego.route")
    half_fov = np.radians(scalars["fov_deg"]) / 2

    vru_valid = np.zeros((B, K), dtype=bool)
    vru_type = np.zeros((B, K), dtype=object)
    numeric = {name: np.zeros((B, K)) for name in ("top", "acc", "rad", "tau", "tval", "tx", "ty", "v0", "bdecel")}
    brake_after = np.full((B, K), math.inf)
    numeric["rad"][:] = 0.1
    vru_mass = np.ones((B, K))
    trigger_kind = np.zeros((B, K), dtype=np.int8)
    motion = _batch_motion(scenarios)
    pack_motion = vru_motion(motion).pack
    path_specs: list = []
    path_index = np.zeros((B, K), dtype=np.int64)
    for b, scenario in enumerate(scenarios):
        for k, vru in enumerate(scenario.vrus):
            vru_valid[b, k] = True
            vru_type[b, k] = vru.type.value
            numeric["rad"][b, k] = vru.footprint_m
            vru_mass[b, k] = vru.body_mass_kg
            (
                numeric["top"][b, k],
                numeric["acc"][b, k],
                numeric["tau"][b, k],
                numeric["v0"][b, k],
                brake_after[b, k],
                numeric["bdecel"][b, k],
            ) = pack_motion(vru)
            trig = vru.trigger
            if trig.at_time_s is not None:
                trigger_kind[b, k], numeric["tval"][b, k] = TRIGGER_TIME, trig.at_time_s
            elif trig.ego_distance_m is not None:
                trigger_kind[b, k], numeric["tval"][b, k] = TRIGGER_DISTANCE, trig.ego_distance_m
            elif trig.ego_route_m is not None:
                trigger_kind[b, k], numeric["tval"][b, k] = TRIGGER_ROUTE, trig.ego_route_m
            elif trig.ego_time_to_arrival_s is None:
                trigger_kind[b, k], numeric["tval"][b, k] = _speed_trigger(trig)
            else:
                trigger_kind[b, k], numeric["tval"][b, k] = (
                    TRIGGER_TIME_TO_ARRIVAL,
                    trig.ego_time_to_arrival_s,
                )
            if trig.point is not None:
                numeric["tx"][b, k], numeric["ty"][b, k] = trig.point.x_m, trig.point.y_m
            path_specs.append(vru_path_spec(vru))
            path_index[b, k] = len(path_specs) - 1
        for k in range(len(scenario.vrus), K):  # empty slot: parked far away, never triggered
            path_specs.append(_PARKED_SLOT)
            path_index[b, k] = len(path_specs) - 1
            trigger_kind[b, k], numeric["tval"][b, k] = TRIGGER_TIME, math.inf
    unique_paths, unique_index = _unique_rows(path_specs)
    vru_paths = PathTable(unique_paths, what="vrus[].path")
    vru_rows = unique_index[path_index]

    max_steer = np.radians(scalars["max_steer_deg"])
    wheelbase = scalars["wheelbase_m"]
    duration = scalars["duration_s"]
    return BatchParams(
        names=[s.name for s in scenarios],
        planner_names=[s.planner.name for s in scenarios],
        planner_params=[_read_only(s.planner.params) for s in scenarios],
        score_profiles=[s.metrics.profile for s in scenarios],
        score_overrides=[s.metrics.score_overrides() for s in scenarios],
        injury_risk_curves=[s.metrics.injury_risk_curve for s in scenarios],
        vru_motion=motion,
        dt_s=dt,
        n_steps=math.ceil(duration.max() / dt - 1e-9),
        duration_s=duration,
        seed=np.array([s.sim.seed for s in scenarios], dtype=np.int64),
        stop_on_collision=np.array([s.sim.stop_on_collision for s in scenarios]),
        stop_at_route_end=np.array([s.sim.stop_at_route_end for s in scenarios]),
        half_length_m=scalars["half_length_m"],
        half_width_m=scalars["half_width_m"],
        wheelbase_m=wheelbase,
        rear_to_centre_m=scalars["rear_to_centre_m"],
        rear_to_front_m=scalars["rear_to_front_m"],
        cruise_speed_mps=scalars["cruise_speed_mps"],
        start_speed_mps=scalars["start_speed_mps"],
        max_accel_mps2=scalars["max_accel_mps2"],
        max_decel_mps2=scalars["max_decel_mps2"],
        max_jerk_mps3=scalars["max_jerk_mps3"],
        lag_s=scalars["lag_s"],
        max_curvature_per_m=np.tan(max_steer) / wheelbase,
        lateral_gain=scalars["lateral_gain"],
        heading_gain=scalars["heading_gain"],
        routes=routes,
        route_offset=route_rows * routes.width,
        route_length_m=scalars["route_length_m"],
        reverse=np.array([s.ego.reverse for s in scenarios]),
        driver=pack_driver([s.ego for s in scenarios]),
        door=pack_door([s.ego for s in scenarios]),
        sensor_enabled=np.array([s.sensor.enabled for s in scenarios]),
        sensor_range_m=scalars["sensor_range_m"],
        sensor_cos_half=np.cos(half_fov),
        sensor_sin_half=np.sin(half_fov),
        obstacles=pack_obstacles([s.obstacles for s in scenarios]),
        sensor=pack_sensor(scenarios),
        v2x_enabled=np.array([s.v2x.enabled for s in scenarios]),
        rsu_x_m=scalars["rsu_x_m"],
        rsu_y_m=scalars["rsu_y_m"],
        comm_range_m=scalars["comm_range_m"],
        coverage_range_m=scalars["coverage_range_m"],
        channel=pack_channel(scenarios, dt),
        vru_valid=vru_valid,
        vru_type=vru_type,
        vru_top_speed_mps=numeric["top"],
        vru_max_accel_mps2=numeric["acc"],
        vru_radius_m=numeric["rad"],
        vru_tau_s=numeric["tau"],
        vru_initial_speed_mps=numeric["v0"],
        vru_brake_after_s=brake_after,
        vru_brake_decel_mps2=numeric["bdecel"],
        vru_paths=vru_paths,
        vru_path_offset=vru_rows * vru_paths.width,
        trigger_kind=trigger_kind,
        trigger_value=numeric["tval"],
        trigger_x_m=numeric["tx"],
        trigger_y_m=numeric["ty"],
        ego_mass_kg=np.array([s.ego.mass_kg for s in scenarios], dtype=float),
        vru_mass_kg=vru_mass,
        tet_ttc_threshold_s=np.array([s.metrics.tet_ttc_threshold_s for s in scenarios], dtype=float),
    )
