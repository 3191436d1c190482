"""End-to-end: the paper's six runs reproduce its outcomes, caption event times and Table II scores."""

from __future__ import annotations

from pathlib import Path

import pytest

from vrusim.metrics.outcome import OUTCOMES
from vrusim.paper.cases import CAPTION_EVENTS, SCORE_TOLERANCE, TABLE_II, TIME_TOLERANCE_S, reproduce


@pytest.fixture(scope="module")
def reproduction() -> dict:
    return reproduce()


def _case(reproduction: dict, key: str, v2x: bool) -> dict:
    return next(c for c in reproduction["cases"] if c["case"] == key and c["v2x"] == v2x)


@pytest.mark.parametrize(("key", "v2x"), list(TABLE_II))
def test_collision_outcome_matches_paper(reproduction, key, v2x):
    case = _case(reproduction, key, v2x)
    expected_collision = TABLE_II[(key, v2x)] == (0.0, 0.0, 0.0)
    assert case["ours"]["collided"] is expected_collision


@pytest.mark.parametrize("event", CAPTION_EVENTS, ids=lambda e: f"{e.case}-{'v2x' if e.v2x else 'sensor'}-{e.field}")
def test_event_time_within_tolerance_of_caption(reproduction, event):
    ours = _case(reproduction, event.case, event.v2x)["ours"]
    value = ours[event.field]
    assert value is not None, f"{event.label}: never happened"
    assert abs(value - event.paper_time_s) <= TIME_TOLERANCE_S


MOTORCYCLIST_V2X = ("motorcyclist", True)
MOTORCYCLIST_V2X_OURS = (0.7333, 0.3813, 0.8532)
"""An accepted, documented deviation from Table II (0.81 / 0.93 / 0.89; docs/paper.md, "Where we differ"): the paper
publishes neither its score formulas nor the details of its Pre-Slow, and no principled reading we tried reproduces
the row. Our FSM pre-slows from the V2X message to a stop and yields; the motorcyclist passes the stopped ego at
1.10 m (safety = proximity term 1.10 / 1.5), the trip takes 16.35 s against 11.67 s free flow (efficiency 0.38), and
comfort agrees within ±0.05. These are today's values, asserted so that any change to them is seen and explained."""


@pytest.mark.parametrize(("key", "v2x"), [key for key in TABLE_II if key != MOTORCYCLIST_V2X])
def test_scores_within_tolerance_of_table_ii(reproduction, key, v2x):
    ours = _case(reproduction, key, v2x)["ours"]
    for name, paper in zip(("safety", "efficiency", "comfort"), TABLE_II[(key, v2x)], strict=True):
        assert abs(ours[name] - paper) <= SCORE_TOLERANCE, f"{name}: ours {ours[name]} vs paper {paper}"


def test_motorcyclist_with_v2x_is_the_documented_deviation(reproduction):
    ours = _case(reproduction, *MOTORCYCLIST_V2X)["ours"]
    assert ours["outcome"] == "avoided"
    assert ours["min_clearance_m"] == pytest.approx(1.10, abs=0.005)
    got = tuple(ours[name] for name in ("safety", "efficiency", "comfort"))
    assert got == pytest.approx(MOTORCYCLIST_V2X_OURS, abs=5e-4)
    assert ours["safety"] == pytest.approx(ours["min_clearance_m"] / 1.5, abs=1e-3)  # the proximity term decides
    paper = TABLE_II[MOTORCYCLIST_V2X]
    assert abs(got[2] - paper[2]) <= SCORE_TOLERANCE  # comfort agrees; safety and efficiency do not
    assert abs(got[0] - paper[0]) > SCORE_TOLERANCE and abs(got[1] - paper[1]) > SCORE_TOLERANCE


def test_match_counts_split_calibrated_collision_and_out_of_sample(reproduction):
    from vrusim.paper.cases import match_counts, match_summary

    counts = match_counts(reproduction)
    assert counts == {
        "outcomes": (6, 6),
        "events": (7, 7),
        "collision": (6, 6),
        "calibrated": (4, 4),
        "out_of_sample": (6, 8),
    }
    assert match_summary(counts) == (
        "6/6 outcomes, 7/7 events; scores: 6/6 follow from a collision, 4/4 calibrated, 6/8 checked out of sample"
    )


def test_v2x_shifts_the_first_reaction_earlier(reproduction):
    for key in ("pedestrian", "motorcyclist"):
        without = _case(reproduction, key, False)["ours"]["first_reaction_s"]
        with_v2x = _case(reproduction, key, True)["ours"]["first_reaction_s"]
        assert with_v2x < without - 0.5


@pytest.mark.parametrize("v2x", [False, True])
def test_escooter_is_followed_stably(v2x):
    """Over a long trip the ego settles behind the e-scooter at its speed and the IDM+ equilibrium gap."""
    from vrusim.engine.simulate import simulate
    from vrusim.metrics.summary import summary_rows
    from vrusim.paper.cases import scenario_dir
    from vrusim.planners.fsm import FsmParams
    from vrusim.scenario.loading import load_scenario
    from vrusim.scenario.schema import Scenario

    data = load_scenario(scenario_dir() / "escooter_leading.yaml").with_v2x(v2x).model_dump()
    data["ego"]["route"]["length_m"] = 900.0
    data["sim"]["duration_s"] = 60.0
    row = summary_rows(simulate([Scenario.model_validate(data)]))[0]
    params = FsmParams.model_validate(data["planner"]["params"])
    lead_speed = 13.4
    equilibrium_gap = params.follow_standstill_gap_m + params.follow_headway_s * lead_speed
    # still following at 13.4 m/s when the 60 s run ends, 900 m route not completed: `incomplete` (issue 17)
    assert row["outcome"] == "incomplete"
    assert row["transitions"][-1]["to"] == "follow"
    assert abs(row["final_speed_mps"] - lead_speed) < 0.05
    assert row["min_clearance_m"] > 0.8 * equilibrium_gap


def test_results_contain_no_nan(reproduction):
    def walk(value):
        if isinstance(value, float):
            assert value == value and value not in (float("inf"), float("-inf"))
        elif isinstance(value, dict):
            for item in value.values():
                walk(item)
        elif isinstance(value, list):
            for item in value:
                walk(item)

    walk(reproduction)


@pytest.mark.parametrize(
    "path", sorted(Path(__file__).resolve().parents[1].glob("scenarios/**/*.yaml")), ids=lambda p: p.stem
)
@pytest.mark.parametrize("v2x", [False, True])
def test_every_shipped_scenario_runs_cleanly(path, v2x):
    """Every YAML file users can copy loads, runs both ways and yields a complete, finite summary."""
    from vrusim.engine.simulate import simulate
    from vrusim.metrics.summary import summary_rows
    from vrusim.scenario.loading import load_scenario

    row = summary_rows(simulate([load_scenario(path).with_v2x(v2x)]))[0]
    assert row["outcome"] in OUTCOMES
    assert all(0.0 <= row[name] <= 1.0 for name in ("safety", "efficiency", "comfort"))
    assert row["end_time_s"] > 0.0
