"""The `predictive` planner: the analytic gentlest deceleration, stopping before the zone, the declared-path
prediction, the paper's cases against the FSM, parameter errors."""

from __future__ import annotations

import numpy as np
import pytest

from vrusim.engine.simulate import simulate
from vrusim.errors import UserInputError
from vrusim.metrics.summary import summary_rows
from vrusim.paper.cases import CASES, paper_scenarios
from vrusim.planners.predictive import PredictiveParams, PredictivePlanner
from vrusim.planners.registry import make_planner

SPEED = 10.0
FRONT_X = 2.25
"""Front bumper of the conftest ego at the start (centre at the origin, 4.5 m long, 1.8 m wide)."""
HALF_WIDTH = 0.9


def crossing(make_scenario, vru: dict, **params):
    """Ego at 10 m/s on a straight road (sensor sees 200 m, 170°) and one VRU; predictive planner."""
    return make_scenario(
        {
            "planner": {"name": "predictive", "params": params},
            "sensor": {"range_m": 200.0, "fov_deg": 170.0},
            "vrus": [vru],
            "sim": {"duration_s": 15.0},
        }
    )


def gentlest(speed: float, tau: float, distance: float) -> float:
    """The analytic gentlest constant deceleration that covers at most `distance` m in `tau` s (>= 0)."""
    if speed * tau <= distance:
        return 0.0
    if speed * tau <= 2.0 * distance:
        return 2.0 * (speed * tau - distance) / tau**2
    return speed**2 / (2.0 * distance)


def test_first_plan_is_the_analytic_gentlest_deceleration(make_scenario):
    """A pedestrian crossing at constant speed: arrive at its zone `time_margin_s` after it has left it."""
    x_vru, y0, v_vru, r = 45.0, -6.0, 1.5, 0.05
    vru = {
        "type": "pedestrian",
        "radius_m": r,
        "start": {"x_m": x_vru, "y_m": y0},
        "heading_deg": 90.0,
        "top_speed_mps": v_vru,
        "initial_speed_mps": v_vru,
    }
    p = PredictiveParams()
    scenario = crossing(make_scenario, vru)
    planner = make_planner("predictive")
    first: list[float] = []
    original = planner.act

    def act(obs):
        command = original(obs)
        if not first:
            first.append(float(planner.required_decel_mps2[0]))
        return command

    planner.act = act
    run = simulate([scenario], planner=planner, trace=True)
    # corridor |y| <= w + r + margin; it leaves it at y = +that, where its circle no longer reaches into the
    # strip the ego sweeps, so the zone starts at its centre station
    leave_s = (HALF_WIDTH + r + p.corridor_margin_m - y0) / v_vru
    expected = gentlest(SPEED, leave_s + p.time_margin_s, x_vru - FRONT_X - p.stop_gap_m)
    assert 0.5 < expected < p.comfort_decel_mps2  # the comfortable, still-moving case
    assert first[0] == pytest.approx(expected, rel=1e-9)
    # and it works: no collision, no emergency, the front reaches the pedestrian's line only after it has left
    m = run.metrics
    assert not m.collided[0]
    assert np.isnan(m.first_mode_s[0, run.mode_names.index("emergency_brake")])
    trace = run.trace
    front_x = trace["ego_x_m"][:, 0] + 2.25 * trace["ego_heading_x"][:, 0]
    at_line = np.argmax(front_x >= x_vru - r)
    assert trace["t_s"][at_line] > leave_s
    assert m.final_speed_mps[0] == pytest.approx(SPEED, abs=0.05)  # back to cruise speed


def test_stops_before_the_zone_when_the_vru_stands_in_the_path(make_scenario):
    x_vru, r = 40.0, 0.5
    vru = {"type": "pedestrian", "radius_m": r, "start": {"x_m": x_vru, "y_m": 0.0}, "heading_deg": 90.0,
           "top_speed_mps": 0.0}  # fmt: skip
    run = simulate([crossing(make_scenario, vru)])
    m = run.metrics
    p = PredictiveParams()
    assert not m.collided[0]
    assert m.final_speed_mps[0] == 0.0
    assert not np.isnan(m.first_mode_s[0, run.mode_names.index("stop")])
    assert np.isnan(m.first_mode_s[0, run.mode_names.index("emergency_brake")])
    front_x = -1.35 + m.final_station_m[0] + 3.6
    assert front_x == pytest.approx(x_vru - r - p.stop_gap_m, abs=0.3)
    assert m.peak_decel_mps2[0] <= p.comfort_decel_mps2 + 0.05


def test_declared_path_prediction_yields_earlier_and_more_gently(make_scenario):
    """A pedestrian walks along the kerb, then turns to cross: only its declared path tells the planner."""
    vru = {
        "type": "pedestrian",
        "start": {"x_m": 26.0, "y_m": -5.0},
        "path": [{"x_m": 30.0, "y_m": -5.0}, {"x_m": 30.0, "y_m": 10.0}],
        "top_speed_mps": 1.5,
        "initial_speed_mps": 1.5,
    }
    base = {"ego": {"start": {"x_m": -30.0, "y_m": 0.0}}}
    runs = {}
    for prediction in ("constant_velocity", "path"):
        scenario = crossing(make_scenario, vru, prediction=prediction)
        scenario = make_scenario(base, scenario.model_dump(mode="json"))
        runs[prediction] = simulate([scenario])
    cv, path = runs["constant_velocity"].metrics, runs["path"].metrics
    names = runs["path"].mode_names
    assert not cv.collided[0] and not path.collided[0]
    assert path.first_mode_s[0, names.index("yield")] < 0.5  # from its first predictions
    assert cv.first_mode_s[0, names.index("yield")] > 2.0  # sees the crossing only once it has turned
    assert path.peak_decel_mps2[0] < cv.peak_decel_mps2[0]


@pytest.fixture(scope="module")
def paper_rows():
    """Summary rows of the six paper runs for the FSM (as in the files) and for the predictive planner."""
    runs = paper_scenarios()
    fsm = summary_rows(simulate([s for _, _, s in runs]))
    predictive = [
        s.model_copy(update={"planner": s.planner.model_copy(update={"name": "predictive", "params": {}})})
        for _, _, s in runs
    ]
    ours = summary_rows(simulate(predictive))
    keyed = {}
    for (case, v2x, _), row_fsm, row_ours in zip(runs, fsm, ours, strict=True):
        keyed[(case.key, v2x)] = (row_fsm, row_ours)
    return keyed


@pytest.mark.parametrize("case", [c.key for c in CASES])
def test_paper_cases_with_v2x_no_collision_and_efficiency_and_comfort_at_least_the_fsms(paper_rows, case):
    fsm, ours = paper_rows[(case, True)]
    assert not ours["collided"]
    assert ours["efficiency"] >= fsm["efficiency"]
    assert ours["comfort"] >= fsm["comfort"]


def test_paper_cases_without_v2x_match_the_fsm_outcomes(paper_rows):
    """Sensor only, the pedestrian and the motorcyclist appear too late for any planner; the e-scooter is followed."""
    for case in ("pedestrian", "escooter", "motorcyclist"):
        fsm, ours = paper_rows[(case, False)]
        assert ours["collided"] == fsm["collided"], case


@pytest.mark.parametrize(
    ("params", "field", "message"),
    [
        ({"prediction": "banana"}, "prediction", "constant_velocity"),
        ({"comfort_decel_mps2": -1.0}, "comfort_decel_mps2", "greater than 0"),
        ({"horizon_s": 100.0}, "horizon_s", "less than or equal to 30"),
        ({"time_margin_s": float("inf")}, "time_margin_s", "finite"),
        ({"speed_envelope": "sometimes"}, "speed_envelope", "valid boolean, got 'sometimes'"),
        ({"horizon_s": True}, "horizon_s", "valid number, got true"),
        ({"gentle": True}, "gentle", "unknown field"),
        ({"comfort_decel_mps2": 9.0}, "emergency_decel_mps2", "at least comfort_decel_mps2"),
        ({"step_s": 1e-7}, "step_s", "greater than or equal to 0.001"),  # 5e7 points a step: the run hung
        ({"step_s": 1e-20}, "step_s", "greater than or equal to 0.001"),  # the count overflowed: no prediction
    ],
)
def test_bad_parameters_name_the_field(make_scenario, params, field, message):
    vru = {"type": "pedestrian", "start": {"x_m": 40.0, "y_m": 0.0}, "heading_deg": 90.0}
    with pytest.raises(UserInputError, match=rf"planner\.params\.{field}: .*{message}"):
        simulate([crossing(make_scenario, vru, **params)])


def test_modes_and_outputs(make_scenario):
    planner = PredictivePlanner()
    assert planner.mode_names == ("cruise", "yield", "follow", "stop", "emergency_brake")
    vru = {"type": "pedestrian", "start": {"x_m": 40.0, "y_m": 0.0}, "heading_deg": 90.0, "top_speed_mps": 0.0}
    run = simulate([crossing(make_scenario, vru)], planner=planner)
    assert run.mode_names == planner.mode_names
    assert planner.required_decel_mps2.shape == (1,)
