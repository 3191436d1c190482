"""Issue 17: safety sees proximity, stalling earns nothing, and scores do not depend on the time limit."""

from __future__ import annotations

import math
from itertools import pairwise
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from vrusim.engine.simulate import simulate
from vrusim.metrics.outcome import outcomes
from vrusim.metrics.safety import proximity_term, safety, ttc_term
from vrusim.metrics.scores import PROFILES, scores
from vrusim.metrics.summary import summary_rows
from vrusim.paper.cases import scenario_dir
from vrusim.scenario.loading import load_scenario
from vrusim.scenario.schema import Scenario
from vrusim.scenario.score_profiles import ScoreProfile

STALLED_FILE = Path(__file__).resolve().parents[1] / "scenarios" / "examples" / "escooter_stationary.yaml"
SCORES = ("safety", "efficiency", "comfort")


def _run(data: dict) -> dict:
    return summary_rows(simulate([Scenario.model_validate(data)]))[0]


def _never_braking_pass(profile: str) -> dict:
    """The paper's pedestrian case, V2X off, planner `none`: the ego passes the pedestrian at 0.57 m."""
    data = load_scenario(scenario_dir() / "pedestrian_crossing.yaml").with_v2x(False).model_dump()
    data["planner"] = {"name": "none"}
    data["metrics"]["profile"] = profile
    return _run(data)


# ------------------------------------------------------------------------------------------- safety


def test_never_braking_pass_scores_safety_below_one():
    row = _never_braking_pass("paper")
    assert row["outcome"] == "avoided" and row["min_ttc_s"] is None
    assert row["min_clearance_m"] == pytest.approx(0.5727, abs=1e-3)
    # TTC term 1 (never on a collision course); proximity term 0.5727 / 1.5 = 0.3818
    assert row["safety"] == pytest.approx(0.3818, abs=1e-4)
    assert (row["efficiency"], row["comfort"]) == (1.0, 1.0)


def test_paper_ttc_profile_keeps_the_old_formula():
    assert _never_braking_pass("paper-ttc")["safety"] == 1.0


def _never_braking_pass_with(**settings: float) -> dict:
    data = load_scenario(scenario_dir() / "pedestrian_crossing.yaml").with_v2x(False).model_dump()
    data["planner"] = {"name": "none"}
    data["metrics"].update(settings)
    return _run(data)


def test_safety_thresholds_can_be_set_per_scenario():
    """`metrics.safety_clearance_threshold_m` / `safety_ttc_threshold_s` replace the profile's thresholds: the
    0.5727 m pass keeps safety 1 under a 0.5 m threshold, scores 0.5727 / 2.5 under 2.5 m, and a TTC-only profile
    gains the proximity term."""
    assert _never_braking_pass_with(safety_clearance_threshold_m=0.5)["safety"] == 1.0
    assert _never_braking_pass_with(safety_clearance_threshold_m=2.5)["safety"] == pytest.approx(0.5727 / 2.5, abs=1e-4)
    assert _never_braking_pass_with(profile="paper-ttc", safety_clearance_threshold_m=1.5)["safety"] == pytest.approx(
        0.3818, abs=1e-4
    )
    braking = load_scenario(scenario_dir() / "pedestrian_crossing.yaml").with_v2x(True).model_dump()
    braking["metrics"]["profile"] = "paper-ttc"  # TTC term alone: min(TTC / threshold, 1)
    assert _run(braking)["safety"] == 1.0  # min TTC 1.87 s above the profile's 1.5 s
    braking["metrics"]["safety_ttc_threshold_s"] = 3.0
    base = _run(braking)
    assert base["outcome"] == "avoided" and base["min_ttc_s"] == pytest.approx(1.869, abs=1e-3)
    assert base["safety"] == pytest.approx(base["min_ttc_s"] / 3.0, abs=5e-4)  # scores are rounded to 0.001
    braking["metrics"]["safety_ttc_threshold_s"] = base["min_ttc_s"]
    relaxed = _run(braking)
    assert relaxed["safety"] == 1.0
    assert (relaxed["efficiency"], relaxed["comfort"]) == (base["efficiency"], base["comfort"])


@pytest.mark.parametrize(
    ("field", "value", "message"),
    [
        ("safety_clearance_threshold_m", 3.5, "less than or equal to 3"),
        ("safety_clearance_threshold_m", 0.0, "greater than 0"),
        ("safety_ttc_threshold_s", -1.0, "greater than 0"),
    ],
)
def test_bad_safety_thresholds_name_the_field(field, value, message):
    from vrusim.errors import UserInputError

    data = load_scenario(scenario_dir() / "pedestrian_crossing.yaml").model_dump()
    data["metrics"][field] = value
    with pytest.raises((UserInputError, ValueError), match=rf"metrics\.{field}.*{message}|{message}"):
        Scenario.model_validate(data)


def test_safety_terms_by_hand():
    assert ttc_term(np.array([0.75, np.inf, -1.0]), 1.5).tolist() == [0.5, 1.0, 0.0]
    assert proximity_term(np.array([0.6, 3.0, -0.1, np.inf]), 1.5).tolist() == pytest.approx([0.4, 1.0, 0.0, 1.0])
    paper = PROFILES["paper"]
    # the more critical term decides: TTC 1.2 s -> 0.8, clearance 0.9 m -> 0.6
    assert safety(paper, np.array([1.2]), np.array([0.9])).tolist() == pytest.approx([0.6])
    assert safety(paper, np.array([0.3]), np.array([0.9])).tolist() == pytest.approx([0.2])


@settings(max_examples=200, deadline=None)
@given(
    c_a=st.floats(-1.0, 50.0),
    c_b=st.floats(-1.0, 50.0),
    ttc=st.floats(0.0, 100.0) | st.just(np.inf),
    name=st.sampled_from(sorted(PROFILES)),
)
def test_safety_is_in_unit_interval_and_monotone_in_clearance(c_a, c_b, ttc, name):
    prof = PROFILES[name]
    s_a, s_b = (float(safety(prof, np.array([ttc]), np.array([c]))[0]) for c in (c_a, c_b))
    assert 0.0 <= s_a <= 1.0 and 0.0 <= s_b <= 1.0
    if c_a <= c_b:
        assert s_a <= s_b
    if prof.clearance_threshold_m is not None and 0.0 <= c_a < prof.clearance_threshold_m:
        assert s_a < 1.0


@settings(max_examples=100, deadline=None)
@given(clearance=st.floats(3.0, 1e6) | st.just(np.inf), name=st.sampled_from(sorted(PROFILES)))
def test_three_metres_of_clearance_keeps_safety_one(clearance, name):
    assert float(safety(PROFILES[name], np.array([np.inf]), np.array([clearance]))[0]) == 1.0


@pytest.mark.parametrize(
    ("field", "value"),
    [("clearance_threshold_m", 3.5), ("clearance_threshold_m", 0.0), ("ttc_threshold_s", -1.0),
     ("jerk_scale_mps3", float("nan"))],
)  # fmt: skip
def test_a_profile_parameter_out_of_range_names_the_field(field, value):
    good = {name: getattr(PROFILES["paper"], name) for name in ScoreProfile.__dataclass_fields__}
    with pytest.raises(ValueError, match=field):
        ScoreProfile(**{**good, field: value})


# ------------------------------------------------------------------------------------------- outcome


def test_outcomes_by_hand():
    got = outcomes(
        collided=np.array([True, False, False, False, False]),
        route_completed=np.array([False, True, False, False, False]),
        cruise_speed_mps=np.array([10.0, 10.0, 10.0, 10.0, 0.0]),
        final_speed_mps=np.array([3.0, 10.0, 0.0, 4.0, 0.0]),
    )
    assert got.tolist() == ["collision", "avoided", "stalled", "incomplete", "avoided"]


@settings(max_examples=100, deadline=None)
@given(travel=st.floats(0.1, 1e4) | st.just(np.inf), rms_j=st.floats(0, 20))
def test_a_stalled_run_earns_no_efficiency(travel, rms_j):
    out = scores(
        np.array([False]), np.array([np.inf]), np.array([travel]), np.array([10.0]), np.array([0.0]),
        np.array([rms_j]), PROFILES["paper"], min_clearance_m=np.array([np.inf]), stalled=np.array([True]),
    )  # fmt: skip
    assert out["efficiency"][0] == 0.0
    assert 0.0 < out["comfort"][0] <= 1.0 and out["safety"][0] == 1.0


def _stalled_rows(duration_s: float) -> dict:
    data = load_scenario(STALLED_FILE).model_dump()
    data["sim"]["duration_s"] = duration_s
    return _run(data)


def test_stalled_escooter_case_is_stalled_with_scores_independent_of_duration():
    rows = [_stalled_rows(d) for d in (25.0, 50.0, 100.0)]
    for row in rows:
        assert row["outcome"] == "stalled"
        assert row["final_speed_mps"] == 0.0 and row["trip_time_s"] is None
        assert [t["to"] for t in row["transitions"]] == ["pre_slow"]  # held for good (the paper's rule)
        assert row["min_clearance_m"] == pytest.approx(29.16, abs=0.01)
        assert row["efficiency"] == 0.0
    assert [tuple(r[s] for s in SCORES) for r in rows] == [tuple(rows[0][s] for s in SCORES)] * 3
    assert rows[0]["moving_time_s"] == rows[2]["moving_time_s"]
    # 15 m/s to 0 at 2 m/s² takes 7.5 s, plus the actuator lag and the jerk ramp
    assert 7.5 < rows[0]["moving_time_s"] < 8.0


def test_incomplete_run_efficiency_never_improves_with_the_time_limit():
    base = load_scenario(scenario_dir() / "escooter_leading.yaml").with_v2x(False).model_dump()
    rows = []
    for duration in (4.0, 6.0, 8.0, 25.0):
        base["sim"]["duration_s"] = duration
        rows.append(_run(base))
    assert [r["outcome"] for r in rows] == ["incomplete", "incomplete", "incomplete", "avoided"]
    efficiency = [r["efficiency"] for r in rows]
    assert all(a >= b for a, b in pairwise(efficiency))
    assert all(math.isfinite(r["trip_time_s"]) for r in rows)


def test_results_say_stalled_and_incomplete_not_avoided():
    """`vrusim.run` results, the paper table and the snapshot figure name the outcome; a stalled or unfinished
    run is not reported as "avoided"."""
    import vrusim
    from vrusim.metrics.outcome import outcome_counts, outcome_of

    stalled = vrusim.run(STALLED_FILE)
    assert "stalled" in repr(stalled) and "avoided" not in repr(stalled)
    rows = [{"outcome": o, "collided": o == "collision"} for o in ("collision", "stalled", "collision", "avoided")]
    assert outcome_counts(rows) == "2 collisions, 1 avoided, 1 stalled"
    assert outcome_of({"collided": True}) == "collision"  # rows saved before outcomes existed
    assert outcome_of({"collided": False}) == "avoided"
