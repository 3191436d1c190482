"""The V2X sensitivity sweep on the paper's pedestrian case: ideal V2X avoids, enough latency or loss collides."""

from __future__ import annotations

import pytest

from vrusim.paper.cases import scenario_dir
from vrusim.scenario.loading import load_scenario
from vrusim.studies.v2x_sensitivity import MAX_BURSTY_LOSS, channel_for, flip, onset, sweep


@pytest.fixture(scope="module")
def pedestrian():
    return load_scenario(scenario_dir() / "pedestrian_crossing.yaml")


def test_latency_flips_the_outcome_between_0_8_and_0_9_s(pedestrian):
    points = sweep(pedestrian, "latency", [0.0, 0.5, 0.8, 0.9, 1.0], seeds=1)
    assert [p.probability for p in points] == [0.0, 0.0, 0.0, 1.0, 1.0]
    assert flip(points) == onset(points) == 0.9


def test_heavy_bernoulli_loss_causes_collisions_light_loss_does_not(pedestrian):
    light, heavy = sweep(pedestrian, "bernoulli", [0.2, 0.95], seeds=40)
    assert light.collisions == 0
    # P(first 8 messages lost) = 0.95^8 = 0.66: well above a third, with 40 seeds
    assert heavy.probability > 0.33


def test_bursty_channel_reaches_the_asked_stationary_loss():
    spec = channel_for("bursty", 0.6)["loss"]
    p_gb, p_bg = spec["p_good_to_bad"], spec["p_bad_to_good"]
    assert p_gb / (p_gb + p_bg) == pytest.approx(0.6)
    with pytest.raises(ValueError, match="exceeds"):
        channel_for("bursty", MAX_BURSTY_LOSS + 0.01)
