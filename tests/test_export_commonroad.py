"""CommonRoad export: files load with commonroad-io, pass its XML schema, and replay the simulation within 1e-6 m."""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import pytest
from commonroad.common.common_scenario import ScenarioID
from commonroad.common.file_reader import CommonRoadFileReader
from commonroad.common.file_writer import CommonRoadFileWriter
from commonroad.geometry.obstacle_shapes.circle_obstacle_shape import CircleObstacleShape
from commonroad.geometry.obstacle_shapes.rect_obstacle_shape import RectObstacleShape
from commonroad.scenario.obstacle import ObstacleType
from commonroad.scenario.scenario import Tag
from commonroad.scenario.state import CustomState

from conftest import PAPER_FILES
from vrusim.errors import UserInputError
from vrusim.interop.commonroad import (
    export_commonroad,
    export_commonroad_all,
    file_stem,
    scenario_id,
    write_recording,
)
from vrusim.interop.commonroad_agents import VRU_OBSTACLE_TYPES, ego_turn_centre_line, route_end_pose
from vrusim.interop.commonroad_lanelets import ARMS
from vrusim.ncap.build import build_test
from vrusim.ncap.grid import select
from vrusim.scenario.loading import load_scenario
from vrusim.scenario.schema import Scenario
from vrusim.version import __version__
from vrusim.viz.recording import Recording, record

TOL_M = 1e-6
"""The export must reproduce every simulated position within this, m (and angles, speeds within 1e-6)."""

CATALOGUE = {
    "CPNCO-50": 3,  # obstruction (parked) cars, pedestrian
    "CPTAns": 0,  # right turn at the intersection
    "CBTAfs": 2,  # left turn, cyclist
    "CPRA-Cs": 0,  # reversing ego, standing pedestrian
}
"""Catalogue scenario code → which of its tests (index in `select`) to export."""


def _polyline_vru_scenario(make_scenario) -> Scenario:
    """A pedestrian on a polyline path (turning on the way) and a standing cyclist, on the minimal scenario."""
    walker = {
        "type": "pedestrian", "start": {"x_m": 20.0, "y_m": -8.0}, "path": [[20.0, -5.0], [23.0, -2.0]],
        "top_speed_mps": 1.5,
    }  # fmt: skip
    standing = {"type": "cyclist", "start": {"x_m": 40.0, "y_m": 6.0}, "heading_deg": 200.0, "top_speed_mps": 0.0}
    changes = {"name": "test polyline/standing", "planner": {"name": "fsm"}, "vrus": [walker, standing]}
    return make_scenario({**changes, "sim": {"duration_s": 4.0}})


@pytest.fixture(scope="module")
def scenarios(make_scenario) -> list[Scenario]:
    paper = [load_scenario(path) for path in PAPER_FILES]
    catalogue = [build_test(select(protocol="2023", codes=[code])[index]).scenario for code, index in CATALOGUE.items()]
    return [*paper, *(s.with_v2x(True) for s in paper), *catalogue, _polyline_vru_scenario(make_scenario)]


@pytest.fixture(scope="module")
def exported(scenarios, tmp_path_factory) -> list[tuple[Recording, Path]]:
    """Each scenario simulated in one batch (the reference) and exported by `export_commonroad` (its own run)."""
    recordings = record(scenarios)
    paths = []
    for scenario in scenarios:
        out = tmp_path_factory.mktemp("cr")
        paths += export_commonroad(scenario, out)
    return list(zip(recordings, paths, strict=True))


@pytest.fixture(scope="module")
def loaded(exported) -> dict[Path, tuple]:
    """Each exported file read back once: path → (CommonRoad scenario, planning problem set)."""
    return {path: CommonRoadFileReader(str(path)).open() for _, path in exported}


def _states(obstacle) -> list:
    return [obstacle.initial_state, *obstacle.prediction.trajectory.state_list]


def _angle_error(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.max(np.abs(np.angle(np.exp(1j * (np.asarray(a) - np.asarray(b)))))))


def test_files_load_pass_the_schema_and_carry_metadata(exported, loaded) -> None:
    for recording, path in exported:
        scenario = recording.scenario
        assert path.name == f"{file_stem(scenario.name)}.xml"
        assert CommonRoadFileWriter.check_validity_of_commonroad_file(path.read_bytes()), path
        cr, problems = loaded[path]
        assert cr.dt == scenario.sim.dt_s
        assert str(cr.scenario_id) == str(scenario_id(scenario.name))
        assert cr.file_information.author == "vrusim"
        assert f"vrusim {__version__}" in cr.file_information.source and scenario.name in cr.file_information.source
        assert Tag.SIMULATED in cr.tags
        assert (Tag.INTERSECTION in cr.tags) == (scenario.road.layout == "intersection")
        assert len(problems.planning_problem_dict) == 1
        assert len(cr.dynamic_obstacles) == 1 + len(scenario.vrus)
        assert len(cr.static_obstacles) == len(scenario.obstacles)
        assert not list(path.parent.glob(".*.tmp"))


def test_every_trajectory_matches_the_simulation(exported, loaded) -> None:
    for recording, path in exported:
        trace, scenario = recording.trace, recording.scenario
        steps = len(recording.t_s)
        cr, _ = loaded[path]
        ego = _states(cr.obstacle_by_id(1))
        assert [s.time_step for s in ego] == list(range(steps))
        assert np.allclose(np.array([s.time_step for s in ego]) * scenario.sim.dt_s, recording.t_s, atol=1e-9)
        xy = np.array([s.position for s in ego])
        assert np.max(np.hypot(xy[:, 0] - trace["ego_x_m"], xy[:, 1] - trace["ego_y_m"])) < TOL_M, scenario.name
        sign = -1.0 if scenario.ego.reverse else 1.0  # a reversing ego faces against its travel, at negative speed
        heading = np.arctan2(sign * trace["ego_heading_y"], sign * trace["ego_heading_x"])
        assert _angle_error([s.orientation for s in ego], heading) < TOL_M
        assert np.max(np.abs(np.array([s.velocity for s in ego]) - sign * trace["ego_speed_mps"])) < TOL_M
        assert np.max(np.abs(np.array([s.acceleration for s in ego]) - sign * trace["ego_accel_mps2"])) < TOL_M
        for v, vru in enumerate(scenario.vrus):
            states = _states(cr.obstacle_by_id(2 + v))
            assert [s.time_step for s in states] == list(range(steps))
            xy = np.array([s.position for s in states])
            gap = np.hypot(xy[:, 0] - trace["vru_x_m"][:, v], xy[:, 1] - trace["vru_y_m"][:, v])
            assert np.max(gap) < TOL_M, scenario.name
            speed = np.array([s.velocity for s in states])
            assert np.max(np.abs(speed - trace["vru_speed_mps"][:, v])) < TOL_M
            if vru.heading_deg is not None:  # a straight path: always its heading (also before it moves)
                heading = np.full(steps, math.radians(vru.heading_deg))
                assert _angle_error([s.orientation for s in states], heading) < TOL_M


def test_polyline_vru_faces_its_direction_of_motion(exported, loaded) -> None:
    recording, path = exported[-1]
    cr, _ = loaded[path]
    walker = _states(cr.obstacle_by_id(2))
    orientation = np.array([s.orientation for s in walker])
    x, y = recording.trace["vru_x_m"][:, 0], recording.trace["vru_y_m"][:, 0]
    assert orientation[0] == pytest.approx(math.pi / 2)  # first leg runs +y, also while standing at the start
    first_leg, second_leg = y < -5.0 - 0.25, x > 20.0 + 0.25
    assert second_leg.any()
    assert _angle_error(orientation[first_leg], np.full(first_leg.sum(), math.pi / 2)) < TOL_M
    assert _angle_error(orientation[second_leg], np.full(second_leg.sum(), math.pi / 4)) < TOL_M


def test_shapes_types_and_parked_cars(exported, loaded) -> None:
    for recording, path in exported:
        scenario = recording.scenario
        cr, _ = loaded[path]
        ego = cr.obstacle_by_id(1)
        assert ego.obstacle_type == ObstacleType.CAR
        assert isinstance(ego.obstacle_shape, RectObstacleShape)
        assert (ego.obstacle_shape.length, ego.obstacle_shape.width) == (scenario.ego.length_m, scenario.ego.width_m)
        for v, vru in enumerate(scenario.vrus):
            obstacle = cr.obstacle_by_id(2 + v)
            assert obstacle.obstacle_type == VRU_OBSTACLE_TYPES[vru.type]
            assert isinstance(obstacle.obstacle_shape, CircleObstacleShape)
            assert obstacle.obstacle_shape.radius == pytest.approx(vru.footprint_m, abs=1e-9)
        for k, box in enumerate(scenario.obstacles):
            parked = cr.obstacle_by_id(2 + len(scenario.vrus) + k)
            assert parked.obstacle_type == ObstacleType.PARKED_VEHICLE
            shape = parked.obstacle_shape
            assert (shape.length, shape.width) == pytest.approx((box.length_m, box.width_m), abs=1e-9)
            assert parked.initial_state.position == pytest.approx([box.centre.x_m, box.centre.y_m], abs=TOL_M)
            assert parked.initial_state.orientation == pytest.approx(math.radians(box.centre.heading_deg), abs=TOL_M)
    kinds = {o.obstacle_type for _, p in exported for o in loaded[p][0].obstacles}
    assert {
        ObstacleType.PEDESTRIAN,
        ObstacleType.BICYCLE,
        ObstacleType.MOTORCYCLE,
        ObstacleType.PARKED_VEHICLE,
    } <= kinds
    assert any(r.scenario.obstacles for r, _ in exported)


def _route_lanelets(cr, scenario: Scenario) -> list[int]:
    """The lanelets the ego's route runs on: its start lanelet; when it turns, then its turn's connection and the
    lane it leads to."""
    network = cr.lanelet_network
    (start,) = network.find_lanelet_by_position([np.array([scenario.ego.start.x_m, scenario.ego.start.y_m])])
    if scenario.road.layout == "straight" or scenario.ego.route.kind == "straight":
        return start
    (incoming,) = [g for i in network.intersections for g in i.incomings if g.incoming_lanelets == set(start)]
    (connection,) = getattr(incoming, f"outgoing_{scenario.ego.route.kind}")
    return [*start, connection, *network.find_lanelet_by_id(connection).successor]


def test_lanelet_network_is_valid_and_carries_the_ego(exported, loaded) -> None:
    for recording, path in exported:
        scenario = recording.scenario
        cr, problems = loaded[path]
        network = cr.lanelet_network
        lanelets = {lanelet.lanelet_id: lanelet for lanelet in network.lanelets}
        assert len(lanelets) == (2 if scenario.road.layout == "straight" else 20)
        for lanelet in lanelets.values():
            assert lanelet.polygon.shapely_object.is_valid, lanelet.lanelet_id
            assert set(lanelet.predecessor) | set(lanelet.successor) <= set(lanelets)
            for successor in lanelet.successor:  # joined: end of this lanelet = start of the next
                assert np.allclose(lanelet.center_vertices[-1], lanelets[successor].center_vertices[0], atol=1e-9)
            if lanelet.adj_left is not None:  # opposite lanes share the centre line, reversed
                other = lanelets[lanelet.adj_left]
                assert np.allclose(lanelet.left_vertices, other.left_vertices[::-1], atol=1e-9)
        # the ego's rectangle centre stays on the lanelets of its route (start lane, turn, exit lane)
        route = set(_route_lanelets(cr, scenario))
        xy = np.array([s.position for s in _states(cr.obstacle_by_id(1))])
        on_route = [bool(set(ids) & route) for ids in network.find_lanelet_by_position(list(xy[::5]))]
        assert all(on_route), scenario.name
        (problem,) = problems.planning_problem_dict.values()
        assert problem.initial_state.position == pytest.approx(xy[0], abs=TOL_M)
        x, y, orientation = route_end_pose(scenario.ego)
        assert problem.goal.is_reached(CustomState(time_step=1, position=np.array([x, y]), orientation=orientation))
        assert not problem.goal.is_reached(CustomState(time_step=1, position=xy[0], orientation=orientation))


def test_intersection_has_every_arm_and_the_egos_own_turn(exported, loaded) -> None:
    turning = [(r.scenario, p) for r, p in exported if r.scenario.ego.route.kind != "straight"]
    assert {s.ego.route.kind for s, _ in turning} == {"left", "right"}
    for scenario, path in turning:
        network = loaded[path][0].lanelet_network
        (intersection,) = network.intersections
        assert len(intersection.incomings) == len(ARMS)
        for group in intersection.incomings:
            turns = (group.outgoing_left, group.outgoing_straight, group.outgoing_right)
            assert all(len(turn) == 1 for turn in turns)
        # the connection the ego turns along is its route's turn (ends moved onto the lane ends by < 5 cm)
        _, connection, _ = _route_lanelets(loaded[path][0], scenario)
        points, _ = ego_turn_centre_line(scenario.ego)
        centre = network.find_lanelet_by_id(connection).center_vertices
        assert np.max(np.linalg.norm(centre - points, axis=1)) < 0.05, scenario.name


def test_names_are_sanitised_for_commonroad_and_files() -> None:
    sid = scenario_id("CPNA-25/20kph/day")
    assert str(sid) == "ZAM_CPNA2520kphDay-1_1_T-1"
    assert str(ScenarioID.from_benchmark_id(str(sid), "2020a")) == str(sid)
    assert str(scenario_id("ü ö")) == "ZAM_Vrusim-1_1_T-1"
    assert file_stem("CPNA-25/20kph/day") == "CPNA-25_20kph_day"
    assert file_stem("../..") == "scenario"


def test_ego_only_as_planning_problem_and_quiet_overwrite(exported, tmp_path, capsys, caplog) -> None:
    recording, _ = exported[0]
    first = write_recording(recording, tmp_path, ego_as_obstacle=False)
    again = write_recording(recording, tmp_path, ego_as_obstacle=False)
    assert first == again and sorted(tmp_path.iterdir()) == [first]
    assert capsys.readouterr().out == "" and not caplog.records
    cr, problems = CommonRoadFileReader(str(first)).open()
    assert [o.obstacle_id for o in cr.dynamic_obstacles] == [2 + v for v in range(len(recording.scenario.vrus))]
    assert len(problems.planning_problem_dict) == 1


def test_unwritable_out_dir_is_a_user_error(tmp_path, monkeypatch) -> None:
    scenario = load_scenario(PAPER_FILES[0])
    with pytest.raises(UserInputError, match="not an existing folder"):
        export_commonroad(scenario, tmp_path / "missing")
    a_file = tmp_path / "file"
    a_file.write_text("")
    with pytest.raises(UserInputError, match="not an existing folder"):
        export_commonroad(scenario, a_file)
    monkeypatch.setattr(os, "access", lambda *args: False)  # the tests may run as root, who may write anywhere
    with pytest.raises(UserInputError, match="permission denied"):
        export_commonroad(scenario, tmp_path)
    assert not list(tmp_path.glob("*.xml"))


def test_export_all_batches_and_matches_single_exports(exported, tmp_path) -> None:
    singles = {path.name: path for _, path in exported[: len(PAPER_FILES)]}
    paper = [recording.scenario for recording, _ in exported[: len(PAPER_FILES)]]
    written = export_commonroad_all(paper, tmp_path)
    assert [p.name for p in written] == list(singles)
    for path in written:
        assert path.read_bytes() == singles[path.name].read_bytes()
    with pytest.raises(UserInputError, match="same CommonRoad file name"):
        export_commonroad_all([paper[0], paper[0].with_v2x(True)], tmp_path)
