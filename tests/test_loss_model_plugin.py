"""A V2X loss model added by a module outside vrusim (tests/extra_loss_model.py): validated, packed, stepped."""

from __future__ import annotations

import numpy as np
import pytest
import yaml

import extra_loss_model
from test_v2x_channel import DT, channel_batch, drive, lost_sequence, v2x_with
from vrusim.engine.simulate import simulate
from vrusim.errors import UserInputError
from vrusim.scenario.loading import load_scenario, scenario_from_mapping
from vrusim.scenario.v2x import loss_schemas
from vrusim.sim.params import pack
from vrusim.sim.v2x.channel import RealisticChannel
from vrusim.sim.v2x.loss.registry import loss_entries

EVERY_THIRD = {"generation": {"mode": "periodic", "rate_hz": 10.0}, "loss": {"model": "every_nth", "every": 3}}


@pytest.fixture
def every_nth():
    extra_loss_model.register()
    yield
    extra_loss_model.unregister()


def test_a_registered_model_drops_every_nth_message(every_nth):
    record = drive(channel_batch(EVERY_THIRD, seeds=[1, 2]), steps=300)
    lost = lost_sequence(record, period_steps=round(0.1 / DT))
    expected = (np.arange(lost.shape[1]) + 1) % 3 == 0
    assert np.array_equal(lost, np.broadcast_to(expected, lost.shape))
    assert record.channel.generated.tolist() == [[30], [30]]
    assert record.channel.delivered.tolist() == [[20], [20]]


def test_a_registered_model_shares_a_batch_with_compiled_ones(every_nth):
    """Variants with a built-in model in the same batch run as they do alone."""
    bernoulli = {**EVERY_THIRD, "loss": {"model": "bernoulli", "probability": 0.3}}
    plugin, builtin = (scenario_from_mapping(v2x_with(channel), "x.yaml") for channel in (EVERY_THIRD, bernoulli))
    mixed = drive(pack([plugin, builtin, plugin]), 300)
    alone = drive(pack([builtin]), 300)
    assert np.array_equal(mixed.message_step[:, 1], alone.message_step[:, 0])
    assert np.array_equal(mixed.message_step[:, 0], mixed.message_step[:, 2])
    assert mixed.channel.delivered.ravel().tolist() == [20, int(alone.channel.delivered[0, 0]), 20]


def test_a_registered_model_runs_from_a_yaml_scenario(every_nth, tmp_path, paper_pedestrian):
    paper_pedestrian["v2x"].update(enabled=True, channel=EVERY_THIRD, comm_range_m=1000.0)  # always in range
    path = tmp_path / "every_third.yaml"
    path.write_text(yaml.safe_dump(paper_pedestrian))
    scenario = load_scenario(path)
    assert scenario.v2x.channel_spec.loss.every == 3
    channel = RealisticChannel()
    simulate([scenario], channel=channel)
    generated, delivered = int(channel.generated.sum()), int(channel.delivered.sum())
    assert generated > 3
    assert delivered == generated - generated // 3


def test_a_bad_parameter_is_refused_naming_the_field(every_nth):
    with pytest.raises(UserInputError, match=r"v2x\.channel\.loss\.every: Input should be greater than or equal"):
        scenario_from_mapping(v2x_with({"loss": {"model": "every_nth", "every": 1}}), "bad.yaml")


def test_unregistered_the_model_is_unknown_again(every_nth):
    extra_loss_model.unregister()
    assert "every_nth" not in loss_schemas() and "every_nth" not in loss_entries()
    with pytest.raises(UserInputError, match="unknown loss model 'every_nth'"):
        scenario_from_mapping(v2x_with(EVERY_THIRD), "x.yaml")
    extra_loss_model.register()  # the fixture unregisters it


def test_built_in_models_cannot_be_unregistered():
    with pytest.raises(ValueError, match="built in"):
        extra_loss_model.unregister_loss_model("bernoulli")
