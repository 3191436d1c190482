"""The scenario's road as a CommonRoad lanelet network (docs/interop.md, "CommonRoad").

The road is the one the figures draw (`viz/scene.py`), in the world frame: a two-way, two-lane road along x
centred on the origin, traffic keeping right (the lane with y < 0 runs towards +x); an intersection adds the
same road along y. Simplifications: one lane per direction; no traffic signs, lights or stop lines; the
intersection's lanes end at a junction square |x|, |y| <= `junction_m` (where a turning ego starts its turn,
see `junction_half_size_m`), across which twelve connection lanelets run: straight lines, and quarter circles
about the square's corners (rounding the drawn sharp kerb corners), except that the connection the ego turns
along follows its route's own turn (clothoids and arc) when that joins the same lane ends. The arms reach at least
`length_m / 2` from the origin, further when the ego's run or route goes past that.
"""

from __future__ import annotations

import math

import numpy as np

from vrusim.extras import extra

with extra("export"):
    from commonroad.common.common_lanelet import LaneletType, LineMarking
    from commonroad.scenario.intersection import IncomingGroup, Intersection
    from commonroad.scenario.lanelet import Lanelet, LaneletNetwork

from vrusim.scenario.schema import Road

VERTEX_SPACING_M = 5.0
"""Largest distance between the vertices of a straight lanelet, m."""

ARC_VERTICES = 17
"""Vertices of a quarter-circle turning connection."""

ARMS: dict[str, tuple[float, float]] = {
    "west": (-1.0, 0.0),
    "east": (1.0, 0.0),
    "south": (0.0, -1.0),
    "north": (0.0, 1.0),
}
"""Outward unit direction of each intersection arm."""


JOIN_TOLERANCE_M = 0.05
"""A turn replaces a connection when its ends lie this close to the connection's ends, m; its end points then
move onto the connection's, so the lanelets still join exactly."""


def road_network(
    road: Road,
    extent_x_m: float,
    extent_y_m: float,
    junction_m: float,
    first_id: int = 1,
    turn: tuple[np.ndarray, np.ndarray] | None = None,
) -> tuple[LaneletNetwork, int]:
    """The lanelet network of `road` and the next unused id. Lanes reach |x| = `extent_x_m` (and |y| =
    `extent_y_m` for an intersection's side road), m; an intersection's arms begin at `junction_m` (>
    `lane_width_m`) from the origin. `turn` (centre-line points [N, 2], m, and headings [N], rad) replaces the
    connection whose ends it joins. Ids count up from `first_id`."""
    if road.layout == "straight":
        lanelets, intersection = _straight_road(road.lane_width_m, extent_x_m, first_id), None
        next_id = first_id + len(lanelets)
    else:
        if junction_m <= road.lane_width_m:
            raise ValueError("junction_m must exceed lane_width_m (the right turns need an inner kerb radius)")
        lanelets, intersection = _intersection(road.lane_width_m, extent_x_m, extent_y_m, junction_m, first_id, turn)
        next_id = intersection.intersection_id + len(intersection.incomings) + 1
    network = LaneletNetwork.create_from_lanelet_list(lanelets, cleanup_ids=False)
    if intersection is not None:
        network.add_intersection(intersection)
    return network, next_id


def _lanelet(
    lanelet_id: int, centre: np.ndarray, heading: np.ndarray, width_m: float, types: set[LaneletType], **links
) -> Lanelet:
    """A lanelet of constant width around centre-line points [N, 2] with headings [N] (rad)."""
    left_normal = np.column_stack([-np.sin(heading), np.cos(heading)])
    return Lanelet(
        left_vertices=centre + left_normal * width_m / 2,
        center_vertices=centre,
        right_vertices=centre - left_normal * width_m / 2,
        lanelet_id=lanelet_id,
        lanelet_type=types,
        **links,
    )


def _line(start: np.ndarray, end: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Points [N, 2] and headings [N] (rad) of a straight centre line from `start` to `end`."""
    count = max(2, math.ceil(float(np.linalg.norm(end - start)) / VERTEX_SPACING_M) + 1)
    points = start + np.linspace(0.0, 1.0, count)[:, None] * (end - start)
    heading = math.atan2(end[1] - start[1], end[0] - start[0])
    return points, np.full(count, heading)


def _straight_road(width_m: float, extent_m: float, first_id: int) -> list[Lanelet]:
    """Two lanelets along x: id `first_id` towards +x (y < 0), `first_id + 1` towards -x (y > 0)."""
    east, west = first_id, first_id + 1
    solid, dashed = LineMarking.SOLID, LineMarking.DASHED
    types = {LaneletType.URBAN}
    centre, heading = _line(np.array([-extent_m, -width_m / 2]), np.array([extent_m, -width_m / 2]))
    eastbound = _lanelet(
        east, centre, heading, width_m, types, adjacent_left=west, adjacent_left_same_direction=False,
        line_marking_left_vertices=dashed, line_marking_right_vertices=solid,
    )  # fmt: skip
    centre, heading = _line(np.array([extent_m, width_m / 2]), np.array([-extent_m, width_m / 2]))
    westbound = _lanelet(
        west, centre, heading, width_m, types, adjacent_left=east, adjacent_left_same_direction=False,
        line_marking_left_vertices=dashed, line_marking_right_vertices=solid,
    )  # fmt: skip
    return [eastbound, westbound]


def _intersection(
    width_m: float,
    extent_x_m: float,
    extent_y_m: float,
    junction: float,
    first_id: int,
    turn: tuple[np.ndarray, np.ndarray] | None,
) -> tuple[list[Lanelet], Intersection]:
    """Four arms (an incoming and an outgoing lanelet each) and twelve connections across the junction box.

    Ids: arm k (in `ARMS` order) has incoming `first_id + 2k` and outgoing `first_id + 2k + 1`; connections
    follow from `first_id + 8`; the Intersection object takes the next id.
    """
    names = list(ARMS)
    incoming = {name: first_id + 2 * k for k, name in enumerate(names)}
    outgoing = {name: first_id + 2 * k + 1 for k, name in enumerate(names)}
    next_id = first_id + 2 * len(names)
    connections: dict[str, dict[str, int]] = {name: {} for name in names}
    lanelets: list[Lanelet] = []
    for a in names:
        for b in names:
            if a == b:
                continue
            kind = _turn_kind(ARMS[a], ARMS[b])
            centre, heading = _connection(ARMS[a], ARMS[b], kind, junction, width_m)
            if turn is not None and _joins(turn[0], centre):
                centre, heading = turn[0].copy(), turn[1]
                centre[[0, -1]] = _connection(ARMS[a], ARMS[b], kind, junction, width_m)[0][[0, -1]]
            lanelets.append(
                _lanelet(
                    next_id, centre, heading, width_m, {LaneletType.URBAN, LaneletType.INTERSECTION},
                    predecessor=[incoming[a]], successor=[outgoing[b]],
                )
            )  # fmt: skip
            connections[a][kind] = next_id
            next_id += 1
    for name in names:
        extent = extent_x_m if ARMS[name][1] == 0.0 else extent_y_m
        d = np.array(ARMS[name])
        right_in = np.array([-d[1], d[0]])  # right of the inward travel direction -d
        into, out_of = incoming[name], outgoing[name]
        centre, heading = _line(d * extent + right_in * width_m / 2, d * junction + right_in * width_m / 2)
        lanelets.append(
            _lanelet(
                into, centre, heading, width_m, {LaneletType.URBAN}, successor=sorted(connections[name].values()),
                adjacent_left=out_of, adjacent_left_same_direction=False,
                line_marking_left_vertices=LineMarking.DASHED, line_marking_right_vertices=LineMarking.SOLID,
            )
        )  # fmt: skip
        centre, heading = _line(d * junction - right_in * width_m / 2, d * extent - right_in * width_m / 2)
        lanelets.append(
            _lanelet(
                out_of, centre, heading, width_m, {LaneletType.URBAN},
                predecessor=sorted(connections[a][_turn_kind(ARMS[a], ARMS[name])] for a in names if a != name),
                adjacent_left=into, adjacent_left_same_direction=False,
                line_marking_left_vertices=LineMarking.DASHED, line_marking_right_vertices=LineMarking.SOLID,
            )
        )  # fmt: skip
    groups = [
        IncomingGroup(
            next_id + 1 + k,
            incoming_lanelets={incoming[name]},
            outgoing_right={connections[name]["right"]},
            outgoing_straight={connections[name]["straight"]},
            outgoing_left={connections[name]["left"]},
        )
        for k, name in enumerate(names)
    ]
    return lanelets, Intersection(next_id, groups)


def _joins(points: np.ndarray, centre: np.ndarray) -> bool:
    """Whether a centre line `points` starts and ends where `centre` does (within `JOIN_TOLERANCE_M`)."""
    ends = np.linalg.norm(points[[0, -1]] - centre[[0, -1]], axis=1)
    return bool(np.all(ends <= JOIN_TOLERANCE_M))


def _turn_kind(from_arm: tuple[float, float], to_arm: tuple[float, float]) -> str:
    """'straight', 'left' or 'right' for travel in from arm `from_arm` and out along arm `to_arm`."""
    (ax, ay), (bx, by) = from_arm, to_arm
    if ax == -bx and ay == -by:
        return "straight"
    cross = (-ax) * by - (-ay) * bx  # z of (travel in) x (travel out): > 0 turns left
    return "left" if cross > 0 else "right"


def _connection(
    from_arm: tuple[float, float], to_arm: tuple[float, float], turn: str, junction_m: float, width_m: float
) -> tuple[np.ndarray, np.ndarray]:
    """Centre line (points [N, 2], headings [N], rad) from the end of arm `from_arm`'s incoming lane to the start
    of arm `to_arm`'s outgoing lane: a line across the junction, or a quarter circle about the box corner."""
    a, b = np.array(from_arm), np.array(to_arm)
    start = a * junction_m + np.array([-a[1], a[0]]) * width_m / 2
    end = b * junction_m - np.array([-b[1], b[0]]) * width_m / 2
    if turn == "straight":
        return _line(start, end)
    corner = (a + b) * junction_m
    radius = float(np.linalg.norm(start - corner))
    sign = 1.0 if turn == "left" else -1.0  # counter-clockwise about the corner when turning left
    first = math.atan2(start[1] - corner[1], start[0] - corner[0])
    angles = first + sign * np.linspace(0.0, math.pi / 2, ARC_VERTICES)
    points = corner + radius * np.column_stack([np.cos(angles), np.sin(angles)])
    points[-1] = end  # exact joint with the outgoing lane
    return points, angles + sign * math.pi / 2
