"""LSC26 §3.1.4 CMFtap SfS: the VUT stopped part-way through the 10 km/h farside turn starts off again.

The VUT follows the FC26 10 km/h farside path (LSC26 §1.2.1) and stands where the front farside corner of its
rectangle reaches the inner side of the (virtual) central lane marking (y = -CENTRAL_MARKING_WIDTH_M / 2 in
the frame of `ncap.build`). Its route begins there (`Route.start_in_turn_m`), so the rest of the turn is the
protocol's own path. It starts off at T0 like every LSC26 standstill start (`build_low_speed.start_off_driver`);
`ncap.build` places the oncoming motorcycle for the first contact on that path.
"""

from __future__ import annotations

import math

import numpy as np

from vrusim.geometry.paths import path_poses
from vrusim.ncap.build_low_speed import GO_SPEED_MPS, LEAD_S, first_step_at_s, start_off_driver, start_off_probe_s
from vrusim.ncap.editions.lsc26 import CENTRAL_MARKING_WIDTH_M, SFS_TURN_PATH_KPH
from vrusim.ncap.test_case import VUT, NcapTest
from vrusim.ncap.turn_placement import (
    EXIT_LENGTH_M,
    ncap_turn_route,
    placed_turn,
    placed_turn_spec,
    route_crossing,
    vut_geometry,
)


def stop_station_m(side: str) -> float:
    """Rear-axle station (m from the turn start) at which the VUT's front farside corner reaches the inner side
    of the central lane marking on the LSC26 SfS turn (`side` "farside": the corner on the left)."""
    samples, _ = placed_turn(side, SFS_TURN_PATH_KPH)
    to_front = vut_geometry(False)[0]
    left = VUT["width_m"] / 2 if side == "farside" else -VUT["width_m"] / 2
    marking_y = -math.copysign(CENTRAL_MARKING_WIDTH_M / 2, left)
    station, _ = route_crossing(samples, to_front, left, np.array([0.0, marking_y]), np.array([1.0, 0.0]))
    return station


def stopped_in_turn_ego(test: NcapTest, contact_station_m: float) -> tuple[dict, float]:
    """The VUT mapping standing at `stop_station_m` (brake held until T0, then the start-off) and the time at
    which it reaches `contact_station_m` (the first contact, m from the turn start) without a reaction, s."""
    side = test.spec.turn
    if side is None:
        raise ValueError(f"{test.test_id}: a start in a turn needs the turn side")
    stop = stop_station_m(side)
    if contact_station_m <= stop:
        raise ValueError(f"{test.test_id}: the first contact lies behind the stop in the turn")
    x, y, heading, _ = path_poses(placed_turn_spec(side, SFS_TURN_PATH_KPH), np.array([stop]))
    to_centre = vut_geometry(False)[1]
    centre = (float(x[0]) + to_centre * math.cos(heading[0]), float(y[0]) + to_centre * math.sin(heading[0]))
    route = ncap_turn_route(side, SFS_TURN_PATH_KPH, 0.0, EXIT_LENGTH_M)
    route = route.model_copy(update={"start_in_turn_m": stop, "length_m": route.length_m - stop})
    ego = {**VUT, "start": {"x_m": centre[0], "y_m": centre[1], "heading_deg": math.degrees(heading[0])}}
    ego.update(cruise_speed_mps=GO_SPEED_MPS, initial_speed_mps=0.0, route=route.model_dump())
    t_go = start_off_probe_s(ego, contact_station_m - stop)
    t0 = first_step_at_s(max(LEAD_S - t_go, 1.0))
    ego["driver"] = start_off_driver(t0)
    return ego, t0 + t_go
