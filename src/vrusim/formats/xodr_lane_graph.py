"""The lane graph of an OpenDRIVE network and the shortest lane sequence between two lanes.

A node is a driving lane (road id, lane id), driven in its direction of travel (`xodr_route.along_s`). It leads
to the lanes that continue it where it ends (ASAM OpenDRIVE 1.6 / 1.8, "Road linkage", "Junctions"):

- a road link (`<successor>` at its s end, `<predecessor>` at its start) to a road: the lane's own `<link>`
  successors / predecessors when given; else the lane of the same id when the linked road is entered at its
  start and of the opposite id when entered at its end (the driving side is kept);
- a link to a junction: every `<connection>` of that junction whose `incomingRoad` is this road, through its
  `<laneLink from to>` (`from` this lane) to the connecting road's lane `to`.

A lane is only entered in its direction of travel from the contact point (a lane that would be driven against
traffic is not a successor). The search (Dijkstra) costs each lane entered by its road's length, or by
(junction roads entered, length) for the `leastIntersections` strategy.
"""

from __future__ import annotations

import heapq
from collections.abc import Callable

from vrusim.errors import UserInputError
from vrusim.formats.xodr_model import Link, Network, Road
from vrusim.formats.xodr_route import along_s

LaneNode = tuple[str, int]
"""(road id, lane id)."""
Cost = Callable[[Road], tuple[float, float]]


def length_cost(road: Road) -> tuple[float, float]:
    """Cost of entering a lane of `road`: its length (shortest, fastest)."""
    return (0.0, road.length_m)


def junction_cost(road: Road) -> tuple[float, float]:
    """Cost of entering a lane of `road`: (1 when it is a junction's connecting road, its length)."""
    return (0.0 if road.junction == "-1" else 1.0, road.length_m)


def _has_lane(road: Road, lane_id: int) -> bool:
    return any(lane.id == lane_id for section in road.sections for lane in (*section.left, *section.right))


def _lane_links(road: Road, lane_id: int, at_end: bool) -> tuple[int, ...]:
    """The lane ids the lane's `<link>` names at that end of `road` (the last / first lane section)."""
    section = road.sections[-1] if at_end else road.sections[0]
    for lane in (*section.left, *section.right):
        if lane.id == lane_id:
            return lane.successors if at_end else lane.predecessors
    return ()


def _enters(network: Network, road_id: str, lane_id: int, at_start: bool) -> list[LaneNode]:
    """[(road, lane)] when lane `lane_id` of road `road_id` exists and is driven away from that end, else []."""
    road = network.roads.get(road_id)
    if road is None or lane_id == 0 or not _has_lane(road, lane_id):
        return []
    return [(road_id, lane_id)] if along_s(road, lane_id) == at_start else []


def successors(network: Network, node: LaneNode) -> list[LaneNode]:
    """The lanes that continue lane `node` where it ends, in file order."""
    road = network.roads[node[0]]
    lane_id = node[1]
    at_end = along_s(road, lane_id)
    link: Link | None = road.successor if at_end else road.predecessor
    if link is None:
        return []
    found: list[LaneNode] = []
    if link.element_type == "road":
        at_start = link.contact_point == "start"
        given = _lane_links(road, lane_id, at_end)
        targets = given if given else ((lane_id,) if at_start else (-lane_id,))
        for target in targets:
            found += _enters(network, link.element_id, target, at_start)
        return found
    junction = network.junctions.get(link.element_id)
    for connection in junction.connections if junction is not None else ():
        if connection.incoming_road != road.id:
            continue
        for from_lane, to_lane in connection.lane_links:
            if from_lane == lane_id:
                found += _enters(network, connection.connecting_road, to_lane, connection.contact_point == "start")
    return found


def shortest_lanes(network: Network, start: LaneNode, goal: LaneNode, cost: Cost = length_cost) -> list[LaneNode]:
    """The lanes from lane `start` (left at its end) to lane `goal` (entered at its start), both included, of
    least total cost; `start` == `goal` searches a loop back to it. UserInputError when none leads there."""
    frontier: list[tuple[tuple[float, float], int, LaneNode]] = []
    came_from: dict[LaneNode, LaneNode] = {}
    best: dict[LaneNode, tuple[float, float]] = {}
    order = 0
    for node in successors(network, start):
        weight = cost(network.roads[node[0]])
        if node not in best or weight < best[node]:
            best[node], came_from[node] = weight, start
            heapq.heappush(frontier, (weight, order := order + 1, node))
    done: set[LaneNode] = set()
    while frontier:
        weight, _, node = heapq.heappop(frontier)
        if node in done:
            continue
        done.add(node)
        if node == goal:
            path = [node]
            while path[-1] != start or len(path) == 1:
                path.append(came_from[path[-1]])
            return path[::-1]
        for following in successors(network, node):
            extra = cost(network.roads[following[0]])
            total = (weight[0] + extra[0], weight[1] + extra[1])
            if following not in done and (following not in best or total < best[following]):
                best[following], came_from[following] = total, node
                heapq.heappush(frontier, (total, order := order + 1, following))
    raise UserInputError(
        f"{network.source or 'OpenDRIVE'}: no lane route from road {start[0]!r} lane {start[1]} "
        f"to road {goal[0]!r} lane {goal[1]} (routes follow lanes through road links and junctions; no lane changes)"
    )
