"""Sensor models are an ordered registry of (name, applies-to-batch check, factory): the first that applies wins."""

from __future__ import annotations

import pytest

from vrusim.sim.params import pack
from vrusim.sim.sensing.registry import (
    register_sensor_model,
    sensor_model_entries,
    sensor_model_entry,
    unregister_sensor_model,
)
from vrusim.sim.sensing.sensor_model import IdealSensor, RealisticSensor, make_sensor_model


class LateSensor(IdealSensor):
    """A stand-in extra model (reports like the ideal one)."""


def _is_late(params) -> bool:
    return bool((params.sensor.latency_steps * params.dt_s >= 0.5).all())


@pytest.fixture
def late():
    register_sensor_model("late", _is_late, LateSensor)
    yield
    unregister_sensor_model("late")


def test_the_built_ins_are_registered_ideal_first():
    assert [entry.name for entry in sensor_model_entries()] == ["ideal", "realistic"]


def test_ideal_settings_pick_ideal_and_others_realistic(make_scenario):
    assert sensor_model_entry(pack([make_scenario()])).name == "ideal"
    noisy = pack([make_scenario({"sensor": {"position_sigma_m": 0.1}})])
    assert sensor_model_entry(noisy).name == "realistic"
    assert type(make_sensor_model(noisy)) is RealisticSensor


def test_a_registered_model_is_checked_first_and_picked_where_it_applies(make_scenario, late):
    assert [entry.name for entry in sensor_model_entries()] == ["late", "ideal", "realistic"]
    slow = pack([make_scenario({"sensor": {"latency_s": 0.6}})])
    assert type(make_sensor_model(slow)) is LateSensor
    assert type(make_sensor_model(pack([make_scenario()]))) is IdealSensor  # does not apply: next entry


def test_an_unregistered_model_is_no_longer_picked(make_scenario):
    slow = pack([make_scenario({"sensor": {"latency_s": 0.6}})])
    register_sensor_model("late", _is_late, LateSensor)
    unregister_sensor_model("late")
    assert type(make_sensor_model(slow)) is RealisticSensor
    assert [entry.name for entry in sensor_model_entries()] == ["ideal", "realistic"]


def test_registration_errors(late):
    with pytest.raises(ValueError, match="'late' is already registered"):
        register_sensor_model("late", _is_late, LateSensor)
    with pytest.raises(ValueError, match="'nope'"):
        register_sensor_model("other", _is_late, LateSensor, before="nope")
    register_sensor_model("last", _is_late, LateSensor, before=None)
    try:
        assert sensor_model_entries()[-1].name == "last"
    finally:
        unregister_sensor_model("last")
