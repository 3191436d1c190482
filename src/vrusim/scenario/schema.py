"""The scenario model: pydantic models validated once, frozen, pure data in SI units.

Field names carry their unit (`_m`, `_s`, `_mps`, `_mps2`, `_mps3`, `_deg`). Positions are in the world frame
(ISO 8855: x forward along the ego's road, y to the left). See docs/scenario.md for every field.
"""

from __future__ import annotations

import math
from typing import Any, Literal, Self

from pydantic import (
    Field,
    SerializerFunctionWrapHandler,
    ValidatorFunctionWrapHandler,
    field_validator,
    model_serializer,
    model_validator,
)

from vrusim.scenario.bounds import path_length_excess
from vrusim.scenario.door import Door
from vrusim.scenario.driver import Driver
from vrusim.scenario.field_paths import replaced
from vrusim.scenario.road_lines import RoadLine, RoadSurface, points_excess
from vrusim.scenario.score_profiles import MAX_CLEARANCE_THRESHOLD_M
from vrusim.scenario.strict import StrictModel, the_one_given
from vrusim.scenario.text import OneLineText, Text
from vrusim.scenario.v2x import ChannelSpec, check_channel, resolve_channel
from vrusim.scenario.vru_masses import EGO_MASS, VRU_MASS
from vrusim.scenario.vru_types import VRU_DEFAULTS, VruType

MAX_STEPS = 10_000_000
"""Most time steps one run may take."""
MAX_SEED = 2**63 - 1
"""Largest `sim.seed`."""
MIN_DT_S = 1e-6
"""Smallest time step, s (1 µs): finer steps add nothing physical, and differences over them (jerk) overflow."""


class Point(StrictModel):
    """A world-frame point, m. YAML may also write it as a two-element list `[x, y]`."""

    x_m: float
    y_m: float

    @model_validator(mode="before")
    @classmethod
    def _from_pair(cls, value: Any) -> Any:
        if isinstance(value, list | tuple):
            if len(value) != 2:
                raise ValueError("a point is [x_m, y_m] or {x_m: .., y_m: ..}")
            return {"x_m": value[0], "y_m": value[1]}
        return value


class Pose(Point):
    """A point with a heading, degrees counter-clockwise from +x."""

    heading_deg: float = 0.0


class Road(StrictModel):
    """Road layout, centred on the world origin. Lanes are two-way: traffic keeps right.

    `lines` / `surfaces` (optional, `vrusim.scenario.road_lines`): the drawn road of an imported network; figures
    draw them instead of the layout. Left out of a dump when not set, so scenarios without them dump as before.
    """

    layout: Literal["straight", "intersection"] = "straight"
    lane_width_m: float = Field(3.5, gt=0)
    length_m: float = Field(200.0, gt=0, description="drawn length of each road arm pair, m")
    lines: list[RoadLine] | None = Field(None, description="drawn road lines (imported roads); None: the layout's")
    surfaces: list[RoadSurface] | None = Field(None, description="drawn paved areas (imported roads)")

    @model_validator(mode="after")
    def _point_budget(self) -> Self:
        reason = points_excess(self.lines, self.surfaces)
        if reason is not None:
            raise ValueError(f"lines and surfaces: {reason}")
        return self

    @model_serializer(mode="wrap")
    def _without_unset_drawing(self, handler: SerializerFunctionWrapHandler) -> dict[str, Any]:
        data = handler(self)
        for name in ("lines", "surfaces"):
            if getattr(self, name) is None:
                data.pop(name, None)
        return data


class Route(StrictModel):
    """The ego's prescribed path (tracked by the rear-axle centre), starting at its start pose.

    straight: a line of `length_m`. left / right: a line of `turn_at_m`, the turn, then a line to the total
    `length_m`. The turn is a circular arc of `radius_m` turning by `angle_deg`; with `clothoid_angle_deg`
    > 0 it is the Euro NCAP turning path instead: a clothoid (curvature 1/`clothoid_entry_radius_m` to
    1/`radius_m`) turning by `clothoid_angle_deg`, the arc, and the mirror-image clothoid back. With
    `start_in_turn_m` > 0 the route begins that far into the turn (no approach line): the ego starts part-way
    through it, facing the turn's tangent there (a VUT stopped in a junction, Euro NCAP LSC26 CMFtap SfS).
    """

    kind: Literal["straight", "left", "right"] = "straight"
    turn_at_m: float = Field(0.0, ge=0)
    radius_m: float = Field(10.0, gt=0)
    angle_deg: float = Field(90.0, gt=0, le=180)
    clothoid_angle_deg: float = Field(0.0, ge=0, lt=90, description="turning angle of each clothoid; 0: none")
    clothoid_entry_radius_m: float = Field(1500.0, gt=0, description="radius where each clothoid meets a line")
    length_m: float = Field(150.0, gt=0, description="route (trip) length, m; travel time is measured over it")
    start_in_turn_m: float = Field(0.0, ge=0, description="the route begins this far into the turn, m; 0: at its start")

    @property
    def clothoid_length_m(self) -> float:
        """Length of each clothoid, m: 2 alpha / (1 / R1 + 1 / R2); 0 without clothoids."""
        alpha = math.radians(self.clothoid_angle_deg)
        return 2 * alpha / (1 / self.clothoid_entry_radius_m + 1 / self.radius_m)

    @property
    def full_turn_length_m(self) -> float:
        """Length of the whole turn (clothoids and arc), m; 0 for a straight route."""
        if self.kind == "straight":
            return 0.0
        return self.radius_m * math.radians(self.angle_deg) + 2 * self.clothoid_length_m

    @property
    def turn_length_m(self) -> float:
        """Length of the turn on this route (the whole turn less `start_in_turn_m`), m; 0 for a straight route."""
        return max(self.full_turn_length_m - self.start_in_turn_m, 0.0)

    @model_validator(mode="after")
    def _turn_fits(self) -> Self:
        if self.kind == "straight":
            if self.start_in_turn_m > 0:
                raise ValueError("start_in_turn_m needs a turn (route.kind left or right)")
            return self
        if self.start_in_turn_m > 0:
            if self.turn_at_m > 0:
                raise ValueError("start_in_turn_m: a route that begins inside its turn has no approach (turn_at_m 0)")
            if self.start_in_turn_m >= self.full_turn_length_m:
                raise ValueError(f"start_in_turn_m must be shorter than the turn ({self.full_turn_length_m:.2f} m)")
        if self.clothoid_angle_deg > 0:
            if self.clothoid_entry_radius_m <= self.radius_m:
                raise ValueError("clothoid_entry_radius_m must be larger than radius_m (the arc radius)")
            total = 2 * self.clothoid_angle_deg + self.angle_deg
            if total > 180:
                raise ValueError(f"the turn 2 clothoid_angle_deg + angle_deg ({total:g} deg) must be at most 180 deg")
        needed = self.turn_at_m + self.turn_length_m
        if needed > self.length_m:
            what = "the arc" if self.clothoid_angle_deg == 0 else "the clothoids and the arc"
            raise ValueError(f"length_m must cover turn_at_m + {what} ({needed:.2f} m)")
        return self


class PathTracking(StrictModel):
    """Gains of the rear-axle path tracker (curvature feedforward + lateral and heading feedback)."""

    lateral_gain_per_m2: float = Field(0.3, gt=0)
    heading_gain_per_m: float = Field(1.2, gt=0)


class Ego(StrictModel):
    """The ego vehicle: a kinematic bicycle. `start` is the centre of its rectangle, facing `start.heading_deg`.

    With `reverse` it drives backwards: the route runs from the start pose against `start.heading_deg`.
    """

    start: Pose
    cruise_speed_mps: float = Field(ge=0)
    initial_speed_mps: float | None = Field(None, ge=0, description="defaults to cruise_speed_mps")
    route: Route = Route()
    reverse: bool = Field(False, description="drives backwards along a straight route; start faces heading_deg")
    length_m: float = Field(4.5, gt=0)
    width_m: float = Field(1.8, gt=0)
    wheelbase_m: float = Field(2.7, gt=0)
    rear_overhang_m: float = Field(0.9, ge=0)
    max_accel_mps2: float = Field(2.0, gt=0)
    max_decel_mps2: float = Field(8.0, gt=0)
    max_jerk_mps3: float | None = Field(None, gt=0, description="None: no jerk limit")
    actuator_lag_s: float = Field(0.0, ge=0, description="first-order lag of the acceleration, s; 0: none")
    max_steer_deg: float = Field(35.0, gt=0, lt=90)
    tracking: PathTracking = PathTracking()
    driver: Driver | None = Field(None, description="the driver's pedal schedule (LSC26); None: no driver model")
    door: Door | None = Field(None, description="a door that opens into a VRU's path (LSC26 CBDA); None: none")
    mass_kg: float = Field(EGO_MASS.mass_kg, ge=100, le=60_000, description="mass for Δv (docs/metrics.md), kg")

    @field_validator("reverse")
    @classmethod
    def _reverse_straight(cls, reverse: bool, info: Any) -> bool:
        route = info.data.get("route")
        if reverse and route is not None and route.kind != "straight":
            raise ValueError(f"reversing needs a straight route (route.kind is {route.kind!r})")
        return reverse

    @model_validator(mode="after")
    def _geometry(self) -> Self:
        if self.wheelbase_m + self.rear_overhang_m > self.length_m:
            raise ValueError("wheelbase_m + rear_overhang_m must not exceed length_m")
        # the arc radius is the tightest of a turn (clothoids run from clothoid_entry_radius_m > radius_m)
        min_radius = self.wheelbase_m / math.tan(math.radians(self.max_steer_deg))
        if self.route.kind != "straight" and self.route.radius_m < min_radius:
            raise ValueError(
                f"route.radius_m {self.route.radius_m} m is tighter than the ego can turn "
                f"(wheelbase_m / tan(max_steer_deg) = {min_radius:.2f} m)"
            )
        if self.door is not None and self.door.hinge_from_front_m + self.door.length_m > self.length_m:
            raise ValueError("door: hinge_from_front_m + length_m must not exceed the ego's length_m")
        return self

    @property
    def start_speed_mps(self) -> float:
        """Speed at t = 0, m/s."""
        return self.cruise_speed_mps if self.initial_speed_mps is None else self.initial_speed_mps

    @property
    def travel_heading_deg(self) -> float:
        """Direction of travel at the start, degrees: `start.heading_deg`, turned by 180 when reversing."""
        return self.start.heading_deg + 180.0 if self.reverse else self.start.heading_deg

    @property
    def trailing_overhang_m(self) -> float:
        """Overhang behind the trailing axle in the direction of travel, m.

        The rear overhang; when reversing, the front overhang `length_m - wheelbase_m - rear_overhang_m`
        (the simulation drives the body mirrored front to back, its "front" being the real rear).
        """
        if self.reverse:
            return self.length_m - self.wheelbase_m - self.rear_overhang_m
        return self.rear_overhang_m


class Obstacle(StrictModel):
    """A static box (e.g. a parked car) that blocks the onboard sensor's line of sight; it never collides."""

    kind: OneLineText = Field("car", min_length=1, description="free label, e.g. 'small car', 'SUV'")
    centre: Pose = Field(description="centre of the rectangle; heading_deg along its length")
    length_m: float = Field(gt=0)
    width_m: float = Field(gt=0)

    def overlaps(self, pose: Pose, length_m: float, width_m: float) -> bool:
        """Whether this box shares interior points with the rectangle `length_m × width_m` centred at `pose`."""
        mine = _corners(self.centre, self.length_m, self.width_m)
        other = _corners(pose, length_m, width_m)
        for corners in (mine, other):  # separating-axis test on the edge directions of both rectangles
            (x0, y0), (x1, y1), (x2, y2) = corners[:3]
            for ax, ay in ((x1 - x0, y1 - y0), (x2 - x0, y2 - y0)):
                a = [x * ax + y * ay for x, y in mine]
                b = [x * ax + y * ay for x, y in other]
                if max(a) <= min(b) or max(b) <= min(a):
                    return False
        return True


def _corners(pose: Pose, length_m: float, width_m: float) -> list[tuple[float, float]]:
    """Corners of a rectangle centred at `pose`: rear-right, rear-left, front-right, front-left."""
    heading = math.radians(pose.heading_deg)
    c, s = math.cos(heading), math.sin(heading)
    return [
        (pose.x_m + c * u * length_m / 2 - s * v * width_m / 2, pose.y_m + s * u * length_m / 2 + c * v * width_m / 2)
        for u in (-1, 1)
        for v in (-1, 1)
    ]


class Sensor(StrictModel):
    """Onboard sector sensor with its apex at the centre of the front bumper.

    The defaults are the ideal sensor (no latency, no missed detection, no noise, daylight); the realism
    fields are modelled in `sim/sensing/sensor_model.py` (docs/models.md, "Sensor model").
    """

    enabled: bool = True
    range_m: float = Field(20.0, gt=0)
    fov_deg: float = Field(120.0, gt=0, le=360, description="full opening angle, in (0, 360]")
    latency_s: float = Field(
        0.0, ge=0, le=10, description="the report at t describes the world at t - latency (whole steps)"
    )
    detection_probability: float = Field(
        1.0, gt=0, le=1, description="chance that a visible VRU is detected in a frame, independent draws"
    )
    position_sigma_m: float = Field(0.0, ge=0, description="std of the Gaussian noise per position axis, m")
    velocity_sigma_mps: float = Field(0.0, ge=0, description="std of the Gaussian noise per velocity axis, m/s")
    frame_rate_hz: float | None = Field(
        None, gt=0, description="new detections at this rate (period in whole steps); None: every step"
    )
    lighting: Literal["day", "night"] = "day"
    night_range_factor: float = Field(0.5, gt=0, le=1, description="range at night = range_m x factor")

    @property
    def effective_range_m(self) -> float:
        """Range of the sector under the scenario's lighting, m: `range_m`, times `night_range_factor` at night."""
        return self.range_m * self.night_range_factor if self.lighting == "night" else self.range_m


class V2X(StrictModel):
    """Roadside unit (RSU) broadcasting VRU awareness messages of the VRUs it perceives."""

    enabled: bool = False
    rsu: Point | None = None
    comm_range_m: float = Field(50.0, gt=0, description="ego receives messages within this distance of the RSU")
    coverage_range_m: float = Field(50.0, gt=0, description="RSU perceives VRUs within this distance")
    channel: str | ChannelSpec = Field("ideal", description="a profile name (V2X_PROFILES) or a channel spec")

    @field_validator("channel", mode="wrap")
    @classmethod
    def _known_channel(cls, value: Any, handler: ValidatorFunctionWrapHandler) -> str | ChannelSpec:
        return check_channel(value)

    @property
    def channel_spec(self) -> ChannelSpec:
        """The channel's specification (a profile name resolved)."""
        return resolve_channel(self.channel)

    @model_validator(mode="after")
    def _rsu_when_enabled(self) -> Self:
        if self.enabled and self.rsu is None:
            raise ValueError("rsu (its position) is required when V2X is enabled")
        return self


class PlannerSpec(StrictModel):
    """Which planner drives the ego, and its parameters (validated by the planner itself)."""

    name: str = "fsm"
    params: dict[str, Any] = Field(default_factory=dict)


_TRIGGER_CONDITIONS = (
    "at_time_s",
    "ego_distance_m",
    "ego_time_to_arrival_s",
    "ego_route_m",
    "ego_speed_below_mps",
    "ego_speed_above_mps",
    "ego_standstill_s",
)


class Trigger(StrictModel):
    """When a VRU starts moving: give exactly one of the conditions (the last three watch the ego's speed at run
    time, so they depend on the planner)."""

    at_time_s: float | None = Field(None, ge=0)
    ego_distance_m: float | None = Field(None, ge=0, description="ego front within this distance of `point`")
    ego_time_to_arrival_s: float | None = Field(None, ge=0, description="ego front distance / speed to `point`")
    ego_route_m: float | None = Field(
        None, ge=0, description="ego (rear axle) has travelled this far along its route, m"
    )
    ego_speed_below_mps: float | None = Field(None, ge=0, description="ego speed at or below this, m/s")
    ego_speed_above_mps: float | None = Field(None, ge=0, description="ego speed at or above this, m/s")
    ego_standstill_s: float | None = Field(None, ge=0, description="ego has stood still (speed 0) this long, s")
    point: Point | None = None

    @model_validator(mode="after")
    def _exactly_one(self) -> Self:
        given = the_one_given(self, _TRIGGER_CONDITIONS)
        if given in ("ego_distance_m", "ego_time_to_arrival_s") and self.point is None:
            raise ValueError(f"{given} needs `point`")
        return self


class VruBrake(StrictModel):
    """A braking phase: a set time after its trigger the VRU decelerates to a standstill."""

    after_trigger_s: float = Field(ge=0, description="delay from the trigger to the start of braking, s")
    decel_mps2: float = Field(gt=0, description="constant deceleration, m/s^2")


class Vru(StrictModel):
    """A vulnerable road user: a point mass moving along a prescribed path from rest to its top speed.

    Before its trigger fires it holds `initial_speed_mps` (0: standing); a `brake` phase, if given, then
    stops it. A `top_speed_mps` of 0 is a stationary target.
    """

    type: VruType = Field(strict=False)  # written as its name
    start: Point
    heading_deg: float | None = Field(None, description="straight path from start in this direction")
    path: list[Point] | None = Field(None, description="polyline waypoints after start")
    top_speed_mps: float | None = Field(None, ge=0)
    initial_speed_mps: float = Field(0.0, ge=0, description="speed at t = 0, held until the trigger fires")
    brake: VruBrake | None = None
    max_accel_mps2: float | None = Field(None, gt=0)
    radius_m: float | None = Field(None, gt=0)
    speed_time_constant_s: float = Field(0.0, ge=0, description="relaxation time toward top speed; 0: none")
    trigger: Trigger = Trigger(at_time_s=0.0)
    motion: str = Field(
        "point_mass", min_length=1, description="VRU motion model by name (vrusim.sim.vru.registry); one per batch"
    )
    mass_kg: float | None = Field(
        None, ge=1, le=1000, description="with its vehicle, for Δv (docs/metrics.md), kg; None: the type's default"
    )

    @field_validator("path")
    @classmethod
    def _path_not_too_long(cls, path: list[Point] | None, info: Any) -> list[Point] | None:
        start = info.data.get("start")
        if path is not None and start is not None:
            reason = path_length_excess([(p.x_m, p.y_m) for p in (start, *path)])
            if reason is not None:
                raise ValueError(reason)
        return path

    @model_validator(mode="after")
    def _one_path(self) -> Self:
        if (self.heading_deg is None) == (self.path is None):
            raise ValueError("give exactly one of heading_deg or path")
        if self.path is not None:
            if len(self.path) < 1:
                raise ValueError("path needs at least one waypoint")
            previous = self.start
            for point in self.path:
                if math.hypot(point.x_m - previous.x_m, point.y_m - previous.y_m) < 1e-6:
                    raise ValueError("path waypoints must differ from the previous point")
                previous = point
        return self

    @property
    def speed_mps(self) -> float:
        """Top speed, m/s (type default when not given)."""
        return self.top_speed_mps if self.top_speed_mps is not None else VRU_DEFAULTS[self.type].top_speed_mps

    @property
    def accel_mps2(self) -> float:
        """Acceleration limit, m/s^2."""
        return self.max_accel_mps2 if self.max_accel_mps2 is not None else VRU_DEFAULTS[self.type].max_accel_mps2

    @property
    def body_mass_kg(self) -> float:
        """Mass with the vehicle ridden, kg (type default when not given)."""
        return self.mass_kg if self.mass_kg is not None else VRU_MASS[self.type].mass_kg

    @property
    def footprint_m(self) -> float:
        """Footprint radius, m."""
        return self.radius_m if self.radius_m is not None else VRU_DEFAULTS[self.type].radius_m


class SimSettings(StrictModel):
    """Integration step, duration and stop conditions."""

    dt_s: float = Field(0.01, gt=0, le=0.1)
    duration_s: float = Field(15.0, gt=0, le=3600)
    seed: int = Field(0, ge=0, lt=MAX_SEED + 1, description="key of the variant's random numbers (sensor, V2X)")
    stop_on_collision: bool = True
    stop_at_route_end: bool = True

    @field_validator("dt_s")
    @classmethod
    def _physical_step(cls, dt_s: float) -> float:
        if dt_s < MIN_DT_S:
            raise ValueError(f"Input should be at least {MIN_DT_S:g} s (1 µs), got {dt_s:g}")
        return dt_s

    @model_validator(mode="after")
    def _enough_steps(self) -> Self:
        if self.duration_s < self.dt_s:
            raise ValueError("duration_s must be at least dt_s")
        if self.duration_s / self.dt_s > MAX_STEPS:
            raise ValueError(f"duration_s / dt_s must be at most {MAX_STEPS:,} steps")
        return self


class MetricsSettings(StrictModel):
    """Which score calibration profile to use, and the settings of the surrogate and injury metrics (see
    docs/metrics.md)."""

    profile: str = "paper"
    tet_ttc_threshold_s: float = Field(
        1.5, gt=0, le=10, description="TTC threshold of TET / TIT, s (default: van der Horst 1990)"
    )
    injury_risk_curve: Literal["rosen_sander_2009", "tefft_2013"] = Field(
        "rosen_sander_2009", description="fatality risk curve (docs/metrics.md, Injury risk)"
    )
    safety_ttc_threshold_s: float | None = Field(
        None, gt=0, le=10, description="TTC threshold of the safety score, s; null: the profile's"
    )
    safety_clearance_threshold_m: float | None = Field(
        None,
        gt=0,
        le=MAX_CLEARANCE_THRESHOLD_M,
        description="clearance threshold of the safety score's proximity term, m; null: the profile's",
    )

    def score_overrides(self) -> dict[str, float]:
        """The safety thresholds set here, as `ScoreProfile` fields (empty: the profile as it is)."""
        chosen = {
            "ttc_threshold_s": self.safety_ttc_threshold_s,
            "clearance_threshold_m": self.safety_clearance_threshold_m,
        }
        return {name: value for name, value in chosen.items() if value is not None}

    @field_validator("profile")
    @classmethod
    def _known_profile(cls, name: str) -> str:
        from vrusim.scenario.score_profiles import PROFILES

        if name not in PROFILES:
            raise ValueError(f"unknown profile {name!r}; expected one of: {', '.join(sorted(PROFILES))}")
        return name


class Scenario(StrictModel):
    """One closed-loop test case: the single source of truth for a run."""

    name: OneLineText = Field(min_length=1)
    description: Text = ""
    road: Road = Road()
    ego: Ego
    sensor: Sensor = Sensor()
    v2x: V2X = V2X()
    planner: PlannerSpec = PlannerSpec()
    vrus: list[Vru] = Field(min_length=1, max_length=64)
    obstacles: list[Obstacle] = Field(default_factory=list, max_length=16)
    sim: SimSettings = SimSettings()
    metrics: MetricsSettings = MetricsSettings()

    @field_validator("vrus")
    @classmethod
    def _vrus_outside_ego(cls, vrus: list[Vru], info: Any) -> list[Vru]:
        ego = info.data.get("ego")
        if ego is None:
            return vrus
        heading = math.radians(ego.start.heading_deg)
        cos_h, sin_h = math.cos(heading), math.sin(heading)
        for index, vru in enumerate(vrus):
            dx, dy = vru.start.x_m - ego.start.x_m, vru.start.y_m - ego.start.y_m
            local_x, local_y = cos_h * dx + sin_h * dy, -sin_h * dx + cos_h * dy
            gap_x = max(abs(local_x) - ego.length_m / 2, 0.0)
            gap_y = max(abs(local_y) - ego.width_m / 2, 0.0)
            if math.hypot(gap_x, gap_y) <= vru.footprint_m:
                raise ValueError(f"vrus[{index}] starts overlapping the ego vehicle")
        return vrus

    @field_validator("obstacles")
    @classmethod
    def _obstacles_clear_of_ego(cls, obstacles: list[Obstacle], info: Any) -> list[Obstacle]:
        ego = info.data.get("ego")
        if ego is None:
            return obstacles
        for index, box in enumerate(obstacles):
            if box.overlaps(ego.start, ego.length_m, ego.width_m):
                raise ValueError(f"obstacles[{index}] overlaps the ego vehicle's start rectangle")
        return obstacles

    @model_validator(mode="after")
    def _door_vru_exists(self) -> Self:
        door = self.ego.door
        if door is not None and door.trigger.vru_distance_m is not None and door.trigger.vru >= len(self.vrus):
            raise ValueError(f"ego.door.trigger.vru: {door.trigger.vru} is not a VRU index (vrus has {len(self.vrus)})")
        return self

    def replace(self, **changes: Any) -> Scenario:
        """A validated copy with the field at each dotted path set: `s.replace(**{"ego.cruise_speed_mps": 12.0})`.

        Paths are YAML keys joined by '.', with `[i]` for a list element (`vrus[0].top_speed_mps`,
        `v2x.channel.latency_s`: a channel profile name is expanded into its specification first). Only the
        models on the changed paths are rebuilt; the copy passes every validator a YAML file would. An unknown
        path or a refused value raises UserInputError naming the path.
        """
        return replaced(self, changes, "Scenario.replace")

    def with_v2x(self, enabled: bool) -> Scenario:
        """A copy with V2X switched on or off (validated again)."""
        data = self.model_dump()
        data["v2x"]["enabled"] = enabled
        return Scenario.model_validate(data)
