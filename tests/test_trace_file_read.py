"""A trace file read back (`engine.trace_file.read_trace`): the arrays the engine recorded, from CSV and Parquet, and
a clear error naming SOURCE for a file `vrusim view` cannot use."""

from __future__ import annotations

import numpy as np
import pyarrow as pa
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


def _edited_csv(run, tmp_path, column: str, cell: str, row: int = 4):
    """A CSV trace with one cell replaced (row from 0, so on line row + 2)."""
    path = tmp_path / "trace.csv"
    write_trace(run, path)
    lines = path.read_text().splitlines()
    header = [name.strip('"') for name in lines[0].split(",")]
    cells = lines[row + 1].split(",")
    cells[header.index(column)] = cell
    lines[row + 1] = ",".join(cells)
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.mark.parametrize(
    ("column", "cell", "problem"),
    [
        ("ego_x_m", "abc", "'abc' is not a number"),
        ("ego_x_m", "inf", "inf is not a finite number"),
        ("ego_x_m", "nan", "has no value"),
        ("t_s", "", "has no value"),
        ("ttc_s", "-inf", "-inf is not a finite number"),
        ("vru0_y_m", "1e999", "inf is not a finite number"),
        ("vru0_detected", "maybe", "'maybe' is not true or false"),
        ("vru0_source", "300", "300 is not 0, 1, 2 or 3"),
    ],
)
def test_a_cell_that_is_no_finite_number_is_named_by_line_and_column(run, tmp_path, column, cell, problem):
    path = _edited_csv(run, tmp_path, column, cell)
    assert_user_error(_view_trace(path, tmp_path), "SOURCE", f"trace.csv: line 6, column {column}: {problem}")
    assert not (tmp_path / "page.html").exists()


def test_a_non_finite_number_in_a_parquet_trace_is_named_by_row(run, tmp_path):
    path = tmp_path / "trace.parquet"
    write_trace(run, path)
    table = pq.read_table(path)
    values = table.column("ego_speed_mps").to_numpy().copy()
    values[2] = np.nan
    pq.write_table(table.set_column(table.column_names.index("ego_speed_mps"), "ego_speed_mps", pa.array(values)), path)
    assert_user_error(_view_trace(path, tmp_path), "SOURCE", "row 3, column ego_speed_mps: nan is not a finite number")


def test_an_empty_ttc_or_v2x_age_is_no_value_not_an_error(run, tmp_path):
    path = _edited_csv(run, tmp_path, "vru0_v2x_age_s", "")
    trace, _ = read_trace(_edited_csv(run, tmp_path, "ttc_s", ""), 1)
    assert np.isinf(trace["ttc_s"][4])
    assert np.isnan(read_trace(path, 1)[0]["vru_v2x_age_s"][4, 0])
