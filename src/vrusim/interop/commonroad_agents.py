"""A traced run's agents as CommonRoad obstacles and the ego's planning problem (docs/interop.md, "CommonRoad").

Trace row i becomes time step i (t = i dt): row 0 is an obstacle's initial state, rows 1.. its trajectory.
Positions are the centres of the shapes in the world frame, which CommonRoad shares (x, y in m, orientation
in rad counter-clockwise from +x).
"""

from __future__ import annotations

import math

import numpy as np

from vrusim.extras import extra

with extra("export"):
    import shapely
    from commonroad.common.util import Interval
    from commonroad.geometry.obstacle_shapes.circle_obstacle_shape import CircleObstacleShape
    from commonroad.geometry.obstacle_shapes.rect_obstacle_shape import RectObstacleShape
    from commonroad.geometry.occupancy.rect_occupancy import RectOccupancy
    from commonroad.planning.goal import GoalRegion
    from commonroad.planning.planning_problem import PlanningProblem
    from commonroad.prediction.prediction import TrajectoryPrediction
    from commonroad.scenario.obstacle import DynamicObstacle, ObstacleType, StaticObstacle
    from commonroad.scenario.state import ExtendedPMState, InitialState
    from commonroad.scenario.trajectory import Trajectory

from vrusim.geometry.paths import path_poses
from vrusim.scenario.routes import ego_route_spec
from vrusim.scenario.schema import Ego, Obstacle, Scenario
from vrusim.scenario.vru_types import VruType
from vrusim.viz.recording import Recording

VRU_OBSTACLE_TYPES: dict[VruType, ObstacleType] = {
    VruType.PEDESTRIAN: ObstacleType.PEDESTRIAN,
    VruType.CYCLIST: ObstacleType.BICYCLE,
    VruType.E_SCOOTER: ObstacleType.BICYCLE,  # no e-scooter type: the closest is the bicycle (docs/interop.md)
    VruType.MOTORCYCLIST: ObstacleType.MOTORCYCLE,
}
"""CommonRoad obstacle type of each VRU type."""

GOAL_LENGTH_FACTOR = 2.0
"""The goal rectangle is this many ego lengths long (along the route's end heading) ..."""

MIN_KERB_RADIUS_M = 1.0
"""... and an intersection's junction square is at least this much larger than the crossing road (half width), m."""

DEFAULT_KERB_RADIUS_M = 6.75
"""Kerb radius of the junction when the ego does not turn, m: with 3.5 m lanes the junction half size is
10.25 m, where the paper's left-turning ego starts its turn (its 12 m turn radius then follows the left-turn
connection exactly)."""


def _states(
    x_m: np.ndarray, y_m: np.ndarray, orientation_rad: np.ndarray, speed_mps: np.ndarray, accel_mps2: np.ndarray
) -> tuple[InitialState, list[ExtendedPMState]]:
    """The initial state (row 0, time step 0) and the trajectory (rows 1.., time steps 1..) of one agent."""
    rows = [
        (np.array([float(x_m[i]), float(y_m[i])]), float(orientation_rad[i]), float(speed_mps[i]), float(accel_mps2[i]))
        for i in range(len(x_m))
    ]
    position, orientation, velocity, acceleration = rows[0]
    initial = InitialState(
        time_step=0, position=position, orientation=orientation, velocity=velocity, acceleration=acceleration,
        yaw_rate=0.0, slip_angle=0.0,
    )  # fmt: skip
    trajectory = [
        ExtendedPMState(time_step=i, position=p, orientation=o, velocity=v, acceleration=a)
        for i, (p, o, v, a) in enumerate(rows[1:], start=1)
    ]
    return initial, trajectory


def _dynamic(
    obstacle_id: int, kind: ObstacleType, shape: RectObstacleShape | CircleObstacleShape, states: tuple
) -> DynamicObstacle:
    initial, trajectory = states
    if not trajectory:
        raise ValueError("a CommonRoad trajectory needs a run of at least one time step")
    prediction = TrajectoryPrediction(Trajectory(1, trajectory), shape)
    return DynamicObstacle(obstacle_id, kind, shape, initial, prediction)


def ego_orientation_rad(recording: Recording) -> np.ndarray:
    """The ego body's orientation per trace row, rad, continuous (unwrapped) from a start in (-pi, pi].

    A reversing ego is simulated mirrored front to back (`Ego.travel_heading_deg`); its body faces against
    its travel direction.
    """
    trace = recording.trace
    hx, hy = trace["ego_heading_x"], trace["ego_heading_y"]
    if recording.scenario.ego.reverse:
        hx, hy = -hx, -hy
    return np.unwrap(np.arctan2(hy, hx))


def ego_obstacle(recording: Recording, obstacle_id: int) -> DynamicObstacle:
    """The ego as a CAR with its rectangle and its simulated trajectory (reversing: negative velocity)."""
    trace, ego = recording.trace, recording.scenario.ego
    sign = -1.0 if ego.reverse else 1.0
    states = _states(
        trace["ego_x_m"], trace["ego_y_m"], ego_orientation_rad(recording),
        sign * trace["ego_speed_mps"], sign * trace["ego_accel_mps2"],
    )  # fmt: skip
    return _dynamic(obstacle_id, ObstacleType.CAR, RectObstacleShape(width=ego.width_m, length=ego.length_m), states)


def vru_orientation_rad(recording: Recording) -> np.ndarray:
    """Each VRU's direction of motion per trace row [T, V], rad: the direction of its last displacement; before
    it first moves (and while it stands) the direction of its path at the start, held."""
    trace = recording.trace
    x, y = trace["vru_x_m"], trace["vru_y_m"]
    out = np.empty(x.shape)
    for v, vru in enumerate(recording.scenario.vrus):
        if vru.heading_deg is not None:
            previous = math.radians(vru.heading_deg)
        else:
            first = vru.path[0] if vru.path else vru.start
            previous = math.atan2(first.y_m - vru.start.y_m, first.x_m - vru.start.x_m)
        out[0, v] = previous
        dx, dy = np.diff(x[:, v]), np.diff(y[:, v])
        moving = np.hypot(dx, dy) > 1e-9
        direction = np.arctan2(dy, dx)
        for i in range(1, len(x)):
            if moving[i - 1]:
                previous = float(direction[i - 1])
            out[i, v] = previous
    return np.unwrap(out, axis=0)


def vru_obstacles(recording: Recording, first_id: int) -> list[DynamicObstacle]:
    """Every VRU as a PEDESTRIAN, BICYCLE or MOTORCYCLE with a circle of its footprint radius and its trajectory.

    Velocity is the simulated speed along the direction of motion; acceleration its forward difference
    (the last row repeats the one before).
    """
    trace, dt = recording.trace, recording.scenario.sim.dt_s
    orientation = vru_orientation_rad(recording)
    speed = trace["vru_speed_mps"]
    accel = np.diff(speed, axis=0, append=speed[-1:]) / dt
    if len(speed) > 1:
        accel[-1] = accel[-2]
    obstacles = []
    for v, vru in enumerate(recording.scenario.vrus):
        states = _states(trace["vru_x_m"][:, v], trace["vru_y_m"][:, v], orientation[:, v], speed[:, v], accel[:, v])
        obstacles.append(
            _dynamic(first_id + v, VRU_OBSTACLE_TYPES[vru.type], CircleObstacleShape(radius=vru.footprint_m), states)
        )
    return obstacles


def parked_obstacles(obstacles: list[Obstacle], first_id: int) -> list[StaticObstacle]:
    """Each static box as a PARKED_VEHICLE rectangle at its centre pose."""
    return [
        StaticObstacle(
            first_id + k,
            ObstacleType.PARKED_VEHICLE,
            RectObstacleShape(width=box.width_m, length=box.length_m),
            InitialState(
                time_step=0,
                position=np.array([box.centre.x_m, box.centre.y_m]),
                orientation=math.radians(box.centre.heading_deg),
                velocity=0.0,
                acceleration=0.0,
                yaw_rate=0.0,
                slip_angle=0.0,
            ),
        )
        for k, box in enumerate(obstacles)
    ]


def route_end_pose(ego: Ego) -> tuple[float, float, float]:
    """Centre (x, y, m) and body orientation (rad) of the ego's rectangle when its rear axle ends its route."""
    spec = ego_route_spec(ego)
    x, y, heading, _ = path_poses(spec, np.array([spec.length_m]))
    ahead = ego.length_m / 2 - ego.trailing_overhang_m  # trailing axle → rectangle centre, along travel
    centre_x = float(x[0]) + ahead * math.cos(heading[0])
    centre_y = float(y[0]) + ahead * math.sin(heading[0])
    body = float(heading[0]) + (math.pi if ego.reverse else 0.0)
    # rounded: commonroad-io writes a goal rectangle's numbers with str(), and the schema rejects '1e-16'
    return round(centre_x, 9), round(centre_y, 9), round(math.atan2(math.sin(body), math.cos(body)), 12)


def planning_problem(recording: Recording, problem_id: int, lane_width_m: float) -> PlanningProblem:
    """The ego's task: its initial state (as the ego obstacle's, yaw rate = speed x route curvature) and a goal
    rectangle `GOAL_LENGTH_FACTOR` ego lengths long and one lane wide centred where its route ends, reached
    within the scenario's duration."""
    scenario = recording.scenario
    ego = ego_obstacle(recording, problem_id)
    start = ego.initial_state
    initial = InitialState(
        time_step=0, position=start.position, orientation=start.orientation, velocity=start.velocity,
        acceleration=start.acceleration,
        yaw_rate=float(recording.trace["ego_speed_mps"][0] * recording.trace["ego_curvature_per_m"][0]),
        slip_angle=0.0,
    )  # fmt: skip
    x, y, orientation = route_end_pose(scenario.ego)
    area = RectOccupancy(
        shapely.Point(x, y),
        width=lane_width_m,
        length=GOAL_LENGTH_FACTOR * scenario.ego.length_m,
        orientation=orientation,
    )
    last_step = max(1, round(scenario.sim.duration_s / scenario.sim.dt_s))
    goal = GoalRegion([InitialState(time_step=Interval(0, last_step), position=area)])
    return PlanningProblem(problem_id, initial, goal)


def junction_half_size_m(scenario: Scenario) -> float:
    """Half size of an intersection's junction square, m: where a turning ego starts its turn (its distance from
    the origin along its start heading), else lane width + `DEFAULT_KERB_RADIUS_M`; at least lane width +
    `MIN_KERB_RADIUS_M`."""
    ego, width = scenario.ego, scenario.road.lane_width_m
    if ego.route.kind == "straight":
        return width + DEFAULT_KERB_RADIUS_M
    spec = ego_route_spec(ego)
    x, y, _, _ = path_poses(spec, np.array([ego.route.turn_at_m]))
    heading = math.radians(ego.travel_heading_deg)
    return max(width + MIN_KERB_RADIUS_M, abs(float(x[0]) * math.cos(heading) + float(y[0]) * math.sin(heading)))


TURN_VERTICES = 41
"""Vertices of the ego's own turning connection."""


def ego_turn_centre_line(ego: Ego) -> tuple[np.ndarray, np.ndarray] | None:
    """The turn of the ego's route (rear-axle path), as centre-line points [N, 2] (m) and headings [N] (rad);
    None for a straight route."""
    route = ego.route
    if route.kind == "straight":
        return None
    stations = route.turn_at_m + np.linspace(0.0, route.turn_length_m, TURN_VERTICES)
    x, y, heading, _ = path_poses(ego_route_spec(ego), stations)
    return np.column_stack([x, y]), heading


def map_extent_m(recording: Recording, margin_m: float) -> tuple[float, float]:
    """How far the lanes along x and along y must reach from the origin, m: half the road length, or past the
    ego's run and route end (plus `margin_m`) when they go further."""
    scenario = recording.scenario
    half = scenario.road.length_m / 2
    end_x, end_y, _ = route_end_pose(scenario.ego)
    xs = np.abs(np.append(recording.trace["ego_x_m"], end_x))
    ys = np.abs(np.append(recording.trace["ego_y_m"], end_y))
    return max(half, float(xs.max()) + margin_m), max(half, float(ys.max()) + margin_m)
