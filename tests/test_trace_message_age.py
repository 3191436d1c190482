"""The V2X message age in traces (`vru_v2x_age_s`): what the ego's channel delivered, recorded with the detections,
written to trace files, read back by `vrusim view`, and carried to the scene player's frames."""

from __future__ import annotations

import numpy as np
import pyarrow.parquet as pq
import pytest

from vrusim.engine.simulate import simulate
from vrusim.engine.trace_file import write_trace
from vrusim.report.player import frames
from vrusim.report.view import read_trace_recording
from vrusim.scenario.loading import scenario_from_mapping
from vrusim.sim.observation import SOURCE_V2X
from vrusim.sources import scenario_of

CASE = "paper:pedestrian"
LATENCY_S, PERIOD_S = 0.1, 0.1


def channel_scenario(latency_s: float = LATENCY_S, rate_hz: float = 1.0 / PERIOD_S):
    """The pedestrian case, V2X on, through a lossless channel: periodic messages at `rate_hz`, `latency_s` late."""
    data = scenario_of(CASE, True).model_dump()
    data["v2x"]["channel"] = {"generation": {"mode": "periodic", "rate_hz": rate_hz}, "latency_s": latency_s}
    return scenario_from_mapping(data, "pedestrian, realistic channel")


def traced(scenario):
    return simulate([scenario], trace=True)


def test_ideal_channel_messages_are_fresh_and_only_where_v2x_delivers():
    trace = traced(scenario_of(CASE, True)).trace
    age, by_v2x = trace["vru_v2x_age_s"][:, 0, 0], (trace["vru_source"][:, 0, 0] & SOURCE_V2X) > 0
    assert by_v2x.any() and (~by_v2x).any()
    assert np.all(age[by_v2x] == 0.0)  # the ideal channel delivers the current state
    assert np.all(np.isnan(age[~by_v2x]))


def test_v2x_off_has_no_message_ages():
    trace = traced(scenario_of(CASE, False)).trace
    assert np.all(np.isnan(trace["vru_v2x_age_s"]))


def test_a_late_periodic_channel_gives_a_sawtooth_between_latency_and_latency_plus_period():
    run = traced(channel_scenario())
    dt = run.params.dt_s
    age = run.trace["vru_v2x_age_s"][:, 0, 0]
    held = np.flatnonzero(np.isfinite(age))
    assert held.size > 100
    assert np.all(age[held] >= LATENCY_S - 1e-9)
    assert np.all(age[held] <= LATENCY_S + PERIOD_S + 1e-9)
    steps = np.diff(age[held])[np.diff(held) == 1]  # consecutive steps that both hold a message
    grows = np.isclose(steps, dt)
    fresh = steps < 0.0  # a newer message arrived
    assert np.all(grows | fresh)
    assert fresh.sum() >= 5  # messages keep arriving, one per period
    assert np.allclose(steps[fresh], -PERIOD_S + dt)  # each replaces one a period older


def test_trace_file_writes_the_age_and_view_reads_it_back(tmp_path):
    scenario = channel_scenario()
    run = traced(scenario)
    path = tmp_path / "trace.parquet"
    write_trace(run, path)
    column = pq.read_table(path).column("vru0_v2x_age_s").to_numpy(zero_copy_only=False)
    expected = run.trace["vru_v2x_age_s"][:, 0, 0]
    assert np.array_equal(np.where(np.isnan(column), -1.0, column), np.where(np.isnan(expected), -1.0, expected))
    recording = read_trace_recording(path, scenario)
    assert np.array_equal(recording.trace["vru_v2x_age_s"][:, 0], expected, equal_nan=True)


def test_view_reads_a_trace_file_without_the_age_column(tmp_path):
    scenario = channel_scenario()
    path = tmp_path / "old.parquet"
    write_trace(traced(scenario), path)
    table = pq.read_table(path)
    pq.write_table(table.drop_columns(["vru0_v2x_age_s"]), path)  # as written before the column existed
    recording = read_trace_recording(path, scenario)
    assert np.all(np.isnan(recording.trace["vru_v2x_age_s"]))
    assert all(age is None for age in frames(recording, 5)["vru_v2x_age_s"][0])


def test_player_frames_carry_the_age_decided_at_each_frame():
    from vrusim.viz.recording import record

    recording = record([channel_scenario()])[0]
    f = frames(recording, 1)
    ages = np.array([np.nan if a is None else a for a in f["vru_v2x_age_s"][0]])
    _, decided = recording.decisions("vru_v2x_age_s")
    assert np.allclose(ages[:-1], decided[:, 0], atol=0.005, equal_nan=True)  # rounded to 0.01 s
    assert np.isfinite(ages).sum() > 100
    assert (np.isfinite(ages) == ((np.array(f["vru_source"][0]) & SOURCE_V2X) > 0)).all()


@pytest.mark.parametrize("latency_s", [0.0, 0.3])
def test_age_never_below_the_latency(latency_s):
    age = traced(channel_scenario(latency_s=latency_s)).trace["vru_v2x_age_s"]
    held = age[np.isfinite(age)]
    assert held.size and held.min() >= latency_s - 1e-9
