"""Score formulas: range, collision rule, monotonicity, calibration profile and error naming."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from vrusim.errors import UserInputError
from vrusim.metrics.scores import PROFILES, profile, scores

PAPER = PROFILES["paper"]


def _score(collided=False, ttc=np.inf, travel=10.0, free=10.0, rms_a=0.0, rms_j=0.0, prof=PAPER, clearance=np.inf):
    out = scores(
        np.array([collided]),
        np.array([ttc]),
        np.array([travel]),
        np.array([free]),
        np.array([rms_a]),
        np.array([rms_j]),
        prof,
        min_clearance_m=np.array([clearance]),
    )
    return {name: float(value[0]) for name, value in out.items()}


def test_collision_scores_zero_whatever_else():
    assert _score(collided=True, ttc=10.0) == {"safety": 0.0, "efficiency": 0.0, "comfort": 0.0}


def test_ideal_run_scores_one():
    assert _score() == {"safety": 1.0, "efficiency": 1.0, "comfort": 1.0}


def test_safety_is_ttc_over_threshold():
    assert _score(ttc=0.75)["safety"] == pytest.approx(0.75 / PAPER.ttc_threshold_s)
    assert _score(ttc=PAPER.ttc_threshold_s * 2)["safety"] == 1.0


def test_efficiency_formula_by_hand():
    travel, free = 12.5, 10.0
    loss = (travel - free) / travel
    expected = 1.0 / (1.0 + (loss / PAPER.loss_scale) ** PAPER.loss_exponent)
    assert _score(travel=travel, free=free)["efficiency"] == pytest.approx(expected)


def test_comfort_formula_by_hand():
    expected = math.exp(-((1.0 / PAPER.accel_scale_mps2) ** 2) - (2.0 / PAPER.jerk_scale_mps3) ** 2)
    assert _score(rms_a=1.0, rms_j=2.0)["comfort"] == pytest.approx(expected)


@settings(max_examples=200, deadline=None)
@given(
    ttc=st.floats(0, 100) | st.just(np.inf),
    travel=st.floats(0.1, 200),
    free=st.floats(0, 200),
    rms_a=st.floats(0, 50),
    rms_j=st.floats(0, 500),
    name=st.sampled_from(sorted(PROFILES)),
)
def test_scores_finite_and_in_unit_interval(ttc, travel, free, rms_a, rms_j, name):
    for value in _score(False, ttc, travel, free, rms_a, rms_j, PROFILES[name]).values():
        assert 0.0 <= value <= 1.0 and math.isfinite(value)


@settings(max_examples=100, deadline=None)
@given(loss_a=st.floats(0, 0.9), loss_b=st.floats(0, 0.9), j_a=st.floats(0, 20), j_b=st.floats(0, 20))
def test_scores_decrease_with_time_loss_and_jerk(loss_a, loss_b, j_a, j_b):
    free = 10.0
    eff_a = _score(travel=free / (1 - loss_a), free=free)["efficiency"]
    eff_b = _score(travel=free / (1 - loss_b), free=free)["efficiency"]
    assert (eff_a >= eff_b - 1e-12) if loss_a <= loss_b else (eff_a <= eff_b + 1e-12)
    com_a, com_b = _score(rms_j=j_a)["comfort"], _score(rms_j=j_b)["comfort"]
    assert (com_a >= com_b) if j_a <= j_b else (com_a <= com_b)


def test_unknown_profile_names_the_field():
    with pytest.raises(UserInputError, match=r"metrics\.profile.*nope"):
        profile("nope")


def test_unknown_profile_in_yaml_is_caught_at_load():
    from vrusim.scenario.loading import scenario_from_mapping

    data = {
        "name": "x",
        "ego": {"start": [0, 0], "cruise_speed_mps": 5},
        "vrus": [{"type": "pedestrian", "start": [50, 5], "heading_deg": 0}],
        "metrics": {"profile": "nope"},
    }
    with pytest.raises(UserInputError, match=r"metrics\.profile: unknown profile 'nope'"):
        scenario_from_mapping(data)
