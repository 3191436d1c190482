"""Planner interface: the FSM's transitions, the `none` planner, plug-ins by `module:Class`, parameter errors."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from vrusim.engine.simulate import simulate
from vrusim.errors import UserInputError
from vrusim.planners.registry import make_planner
from vrusim.scenario.loading import scenario_from_mapping


class BrakeOnDetection:
    """A user planner: full braking as soon as anything is detected (used by the plug-in test)."""

    mode_names = ("drive", "brake")

    def reset(self, params):
        self.mode = np.zeros(params.size, dtype=np.int8)

    def act(self, observation):
        seen = observation.detected.any(axis=1)
        self.mode = np.where(seen | (self.mode == 1), 1, 0).astype(np.int8)
        return np.where(self.mode == 1, -8.0, 0.0)


def _crossing(planner: str = "fsm", v2x: bool = False, **params) -> dict:
    return {
        "name": "crossing",
        "ego": {"start": {"x_m": -50, "y_m": -1.75}, "cruise_speed_mps": 10.0, "route": {"length_m": 120}},
        "v2x": {"enabled": v2x, "rsu": {"x_m": 20, "y_m": 5}, "comm_range_m": 80, "coverage_range_m": 30},
        "planner": {"name": planner, "params": params},
        "vrus": [
            {
                "type": "pedestrian",
                "start": {"x_m": 10, "y_m": -8},
                "heading_deg": 90,
                "trigger": {"at_time_s": 2.0},
            }
        ],
        "sim": {"duration_s": 20},
    }


def test_fsm_records_every_transition_in_order():
    run = simulate([scenario_from_mapping(_crossing(v2x=True))])
    transitions = run.metrics.transitions
    names = [(run.mode_names[a], run.mode_names[b]) for _, _, a, b in transitions]
    assert names[0][0] == "cruise"
    assert ("cruise", "pre_slow") in names or ("cruise", "emergency_brake") in names
    assert names[-1][1] == "cruise"  # back to cruise once the pedestrian has cleared
    times = [t for t, *_ in transitions]
    assert times == sorted(times)
    for (_, _, _, to), (_, _, frm, _) in itertools.pairwise(transitions):
        assert to == frm  # each transition starts where the previous one ended


def test_none_planner_holds_speed_and_hits():
    run = simulate([scenario_from_mapping(_crossing(planner="none"))])
    assert run.metrics.collided[0]
    assert run.metrics.impact_ego_speed_mps[0] == pytest.approx(10.0)


def test_plugin_planner_by_module_path():
    scenario = scenario_from_mapping(_crossing(planner="tests.test_planners:BrakeOnDetection"))
    run = simulate([scenario])
    assert run.mode_names == ("drive", "brake")
    assert run.metrics.final_speed_mps[0] == 0.0
    assert not run.metrics.collided[0]


@pytest.mark.parametrize(
    ("name", "message"),
    [
        ("warp", "unknown planner 'warp'"),
        ("no_such_module:X", "cannot import"),
        ("vrusim.errors:UserInputError", "reset"),
    ],
)
def test_bad_planner_name_is_a_user_error(name, message):
    with pytest.raises(UserInputError, match=r"planner\.name") as error:
        make_planner(name)
    assert message in str(error.value)


def test_bad_fsm_parameter_names_the_field():
    with pytest.raises(UserInputError, match=r"planner\.params\.pre_slow_decel_mps2"):
        simulate([scenario_from_mapping(_crossing(pre_slow_decel_mps2=-1))])
    with pytest.raises(UserInputError, match=r"planner\.params\.brake_hard.*unknown field"):
        simulate([scenario_from_mapping(_crossing(brake_hard=True))])


class BrakeOnConflict:
    """A NumPy planner built on the shared ConflictTracker: brake hard while any VRU conflicts with the path."""

    mode_names = ("drive", "brake")

    def reset(self, params):
        from vrusim.planners.conflict import ConflictTracker

        ones = np.ones(params.size)
        self.tracker = ConflictTracker(horizon_s=5.0 * ones, margin_m=0.25 * ones, memory_s=1.0 * ones)
        self.mode = np.zeros(params.size, dtype=np.int8)

    def act(self, observation):
        facts = self.tracker.analyse(observation)
        self.mode = facts.conflict.any(axis=1).astype(np.int8)
        return np.where(self.mode == 1, -6.0, 0.0)


def test_conflict_tracker_flags_the_crossing_pedestrian_from_the_first_v2x_message():
    from vrusim.paper.cases import scenario_dir
    from vrusim.scenario.loading import load_scenario

    scenario = load_scenario(scenario_dir() / "pedestrian_crossing.yaml").with_v2x(True)
    run = simulate([scenario], planner=BrakeOnConflict())
    first_brake = run.metrics.first_mode_s[0, 1]
    assert first_brake == pytest.approx(run.metrics.first_v2x_s[0])
    assert not run.metrics.collided[0]
