"""A trace file read back (`engine.trace_file.read_trace`): the arrays the engine recorded, from CSV and Parquet, and
a clear error naming SOURCE for a file `vrusim view` cannot use."""

from __future__ import annotations

import numpy as np
import pyarrow.parquet as pq
import pytest

from cli_helpers import assert_user_error, invoke
from vrusim.engine.simulate import simulate
from vrusim.engine.trace_file import EGO_COLUMNS, read_trace, write_trace
from vrusim.sources import scenario_of

CASE = "paper:pedestrian"


@pytest.fixture(scope="module")
def run():
    return simulate([scenario_of(CASE, True)], trace=True)


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_every_recorded_column_reads_back_exactly(run, tmp_path, suffix):
    path = tmp_path / f"trace{suffix}"
    write_trace(run, path)
    trace, names = read_trace(path, 1)
    assert np.array_equal(trace["t_s"], np.round(run.trace["t_s"], 9))  # written rounded to 1 ns
    for name in (*EGO_COLUMNS, "clearance_m", "ttc_s"):
        assert np.array_equal(trace[name], run.trace[name][:, 0]), name
    for name in ("vru_x_m", "vru_y_m", "vru_speed_mps", "vru_detected", "vru_source", "vru_v2x_age_s"):
        assert np.array_equal(trace[name], run.trace[name][:, 0], equal_nan=name == "vru_v2x_age_s"), name
    assert np.allclose(trace["ego_heading_x"], run.trace["ego_heading_x"][:, 0], atol=1e-12)
    assert np.allclose(trace["ego_heading_y"], run.trace["ego_heading_y"][:, 0], atol=1e-12)
    modes = [run.mode_names[m] for m in run.trace["planner_mode"][:, 0]]
    assert [names[m] for m in trace["planner_mode"]] == modes
    assert np.isinf(trace["ttc_s"]).any()  # written as null, read back as infinite


def _view_trace(path, tmp_path):
    return invoke("view", path, "--scenario", CASE, "--out", tmp_path / "page.html", "--no-open")


@pytest.mark.parametrize(
    ("edit", "names"),
    [
        (lambda table: table.drop_columns(["ego_x_m"]), ("SOURCE", "ego_x_m")),
        (lambda table: table.drop_columns(["vru0_x_m"]), ("SOURCE", "1 VRUs")),
        (lambda table: table.slice(0, 0), ("SOURCE", "no trace rows")),
    ],
)
def test_a_trace_view_cannot_use_is_one_message_naming_source(run, tmp_path, edit, names):
    path = tmp_path / "trace.parquet"
    write_trace(run, path)
    pq.write_table(edit(pq.read_table(path)), path)
    assert_user_error(_view_trace(path, tmp_path), *names)
    assert not (tmp_path / "page.html").exists()


def test_a_file_that_is_no_trace_is_one_message_naming_source(tmp_path):
    path = tmp_path / "trace.parquet"
    path.write_bytes(b"not parquet")
    assert_user_error(_view_trace(path, tmp_path), "SOURCE", "cannot read trace")
