"""The Gym's per-step reward, term by term by hand (docs/interop.md, "Reward"): the danger term reads TTC and,
like the safety score, clearance; the scenario's `metrics.safety_*` thresholds apply."""

from __future__ import annotations

import numpy as np
import pytest

from vrusim.gym.reward import RewardModel, RewardWeights
from vrusim.gym.stepper import EpisodeStep
from vrusim.paper.cases import scenario_dir
from vrusim.scenario.loading import load_scenario
from vrusim.scenario.schema import Scenario
from vrusim.sim.params import pack

WEIGHTS = RewardWeights(progress=0.0, comfort=0.0, safety=1.0, collision=0.0, scores=0.0)
"""The danger term alone."""


def _model(**metrics) -> tuple[RewardModel, float]:
    data = load_scenario(scenario_dir() / "pedestrian_crossing.yaml").model_dump()
    data["metrics"].update(metrics)
    params = pack([Scenario.model_validate(data)])
    return RewardModel(params, WEIGHTS), float(params.dt_s / (params.route_length_m[0] / params.cruise_speed_mps[0]))


def _step(ttc_s: float, clearance_m: float) -> EpisodeStep:
    one = np.ones(1, dtype=bool)
    zero = np.zeros(1)
    return EpisodeStep(
        was_active=one,
        reason=np.zeros(1, dtype=np.int8),
        terminated=~one,
        truncated=~one,
        collided=~one,
        progress_m=zero,
        accel_mps2=zero,
        jerk_mps3=zero,
        min_ttc_s=np.array([ttc_s]),
        min_clearance_m=np.array([clearance_m]),
    )


@pytest.mark.parametrize(
    ("ttc_s", "clearance_m", "danger"),
    [
        (np.inf, 10.0, 0.0),  # far and no collision course
        (0.75, 10.0, 0.5),  # TTC half the 1.5 s threshold
        (np.inf, 0.6, 0.6),  # a pass at 0.6 m: 1 - 0.6 / 1.5
        (0.3, 0.9, 0.8),  # the more critical term: TTC 0.8 against clearance 0.4
        (np.inf, -0.2, 1.0),  # overlapping
    ],
)
def test_danger_is_the_more_critical_of_ttc_and_clearance(ttc_s, clearance_m, danger):
    model, step_weight = _model()  # paper profile: TTC 1.5 s, clearance 1.5 m
    reward = model.step(_step(ttc_s, clearance_m), None)
    assert reward[0] == pytest.approx(-danger * step_weight, rel=1e-12, abs=1e-15)


def test_a_ttc_only_profile_and_the_scenario_thresholds():
    model, step_weight = _model(profile="paper-ttc")
    assert model.step(_step(np.inf, 0.6), None)[0] == 0.0  # no proximity term in paper-ttc
    model, step_weight = _model(profile="paper-ttc", safety_clearance_threshold_m=2.0, safety_ttc_threshold_s=3.0)
    assert model.step(_step(np.inf, 0.6), None)[0] == pytest.approx(-0.7 * step_weight)
    assert model.step(_step(1.5, 10.0), None)[0] == pytest.approx(-0.5 * step_weight)
