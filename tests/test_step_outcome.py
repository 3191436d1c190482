"""A step of the engine returns which variants stopped and why (`StepOutcome`); the Gym ends episodes by it."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from vrusim.engine.stepper import BatchStepper, StopReason
from vrusim.sim.params import pack

STANDING = {"type": "pedestrian", "start": {"x_m": 32.0, "y_m": 0.0}, "heading_deg": 90.0, "top_speed_mps": 0.0}
"""A pedestrian standing on the ego's lane 30 m ahead of its front: hit at about 3 s at 10 m/s."""


@pytest.fixture
def batch(make_scenario):
    """Variant 0 collides (~3 s), variant 1 reaches its 20 m route end (~2 s), variant 2 times out at 1 s."""
    return pack(
        [
            make_scenario({"vrus": [STANDING]}),
            make_scenario({"ego": {"route": {"kind": "straight", "length_m": 20.0}}}),
            make_scenario({"sim": {"duration_s": 1.0}}),
        ]
    )


def _run(stepper) -> tuple[np.ndarray, np.ndarray]:
    """Hold speed until every variant stopped; each variant's stop reason and the time it stopped, s."""
    size = stepper.params.size
    reasons, times = np.zeros(size, dtype=int), np.full(size, np.nan)
    while True:
        stepper.observe()
        outcome = stepper.advance(np.zeros(size))
        assert not (outcome.stopped & (reasons > 0)).any()  # each variant stops once
        reasons[outcome.stopped], times[outcome.stopped] = outcome.reason[outcome.stopped], stepper.t_s
        assert outcome.running == stepper.active.sum() == (reasons == 0).sum()
        if outcome.running == 0:
            return reasons, times


def test_a_step_says_which_variants_stopped_and_why(batch):
    reasons, times = _run(BatchStepper(batch))
    assert list(reasons) == [StopReason.COLLISION, StopReason.ROUTE_END, StopReason.TIME_UP]
    assert times[0] == pytest.approx(3.0, abs=0.1)
    assert times[1] == pytest.approx(2.0, abs=0.05)
    assert times[2] == pytest.approx(1.0)


def test_after_the_batch_s_last_step_every_variant_has_timed_out(batch):
    reasons, times = _run(BatchStepper(dataclasses.replace(batch, n_steps=50)))
    assert list(reasons) == [StopReason.TIME_UP] * 3
    assert np.allclose(times, 0.5)


def test_collision_wins_over_the_other_reasons_in_the_same_step(make_scenario):
    """Collision and time up in the same step: the collision is the reason."""
    reasons, _ = _run(BatchStepper(pack([make_scenario({"vrus": [STANDING], "sim": {"duration_s": 2.5}})])))
    assert list(reasons) == [StopReason.TIME_UP]
    (hit_at,) = _run(BatchStepper(pack([make_scenario({"vrus": [STANDING]})])))[1]
    reasons, _ = _run(BatchStepper(pack([make_scenario({"vrus": [STANDING], "sim": {"duration_s": hit_at}})])))
    assert list(reasons) == [StopReason.COLLISION]


def test_gym_episodes_end_with_the_engine_s_reasons(batch):
    pytest.importorskip("gymnasium")
    from vrusim.gym.stepper import EpisodeStepper

    episodes = EpisodeStepper(batch)
    terminated, truncated = np.zeros(batch.size, dtype=bool), np.zeros(batch.size, dtype=bool)
    reasons = np.zeros(batch.size, dtype=int)
    while not (terminated | truncated).all():
        episodes.observe()
        step = episodes.advance(np.zeros(batch.size))
        assert not (step.reason.astype(bool) & ~step.was_active).any()
        reasons[step.reason > 0] = step.reason[step.reason > 0]
        terminated |= step.terminated
        truncated |= step.truncated
    assert list(reasons) == [StopReason.COLLISION, StopReason.ROUTE_END, StopReason.TIME_UP]
    assert list(terminated) == [True, True, False] and list(truncated) == [False, False, True]


def test_outcomes_stay_valid_after_later_steps_and_are_read_only(batch):
    """Quiet steps share one outcome of zeros; a stopping step's reasons are its own copy, never overwritten."""
    stepper, outcomes = BatchStepper(batch), []
    while not outcomes or outcomes[-1].running:
        stepper.observe()
        outcomes.append(stepper.advance(np.zeros(batch.size)))
    stops = [o for o in outcomes if o.stopped.any()]
    assert [list(o.reason) for o in stops] == [[0, 0, StopReason.TIME_UP], [0, StopReason.ROUTE_END, 0],
                                               [StopReason.COLLISION, 0, 0]]  # fmt: skip
    assert all(not o.reason.any() for o in outcomes if not o.stopped.any())
    for outcome in outcomes:
        with pytest.raises(ValueError, match="read-only"):
            outcome.reason[0] = 1
