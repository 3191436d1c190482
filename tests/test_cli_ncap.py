"""`vrusim ncap` and `vrusim list`: outputs, their agreement with each other, and user errors (exit code 2)."""

from __future__ import annotations

import json
import math

import pyarrow.csv as pa_csv
import pyarrow.parquet as pq
import pytest

from cli_helpers import assert_user_error, invoke
from vrusim.ncap.editions.v2023 import SCENARIOS
from vrusim.ncap.grid import select


@pytest.fixture(scope="module")
def ncap_out(tmp_path_factory):
    """`vrusim ncap --scenario CPNA-75 --scenario CPTA --night --out DIR --json`: the JSON and the folder."""
    folder = tmp_path_factory.mktemp("ncap") / "out"
    result = invoke(
        "ncap",
        "--protocol",
        "2023",
        "--scenario",
        "CPNA-75",
        "--scenario",
        "CPTA",
        "--night",
        "--out",
        folder,
        "--json",
    )
    assert result.exit_code == 0, result.output
    return json.loads(result.stdout), folder


def test_ncap_writes_rows_that_match_the_assessment(ncap_out):
    document, folder = ncap_out
    assert sorted(p.name for p in folder.iterdir()) == ["results.csv", "results.parquet", "scorecard.png"]
    expected = {t.test_id for t in select(protocol="2023", codes=["CPNA-75", "CPTA"], night=True)}
    tests = {t["test_id"]: t for t in document["assessment"]["tests"]}
    assert set(tests) == expected
    csv_rows = pa_csv.read_csv(folder / "results.csv").to_pylist()
    parquet_rows = pq.read_table(folder / "results.parquet").to_pylist()
    assert [r["test_id"] for r in csv_rows] == [r["test_id"] for r in parquet_rows]
    assert {r["test_id"] for r in parquet_rows} == expected
    for row in parquet_rows:
        assessed = tests[row["test_id"]]
        assert row["colour"] == assessed["colour"]
        assert row["sub_score"] == assessed["sub_score"]
        assert row["collided"] == assessed["collided"]
        assert row["planner"] == "fsm" and row["v2x"] is False
        for value in row.values():
            assert not (isinstance(value, float) and math.isnan(value))
    assert (folder / "scorecard.png").stat().st_size > 10_000


def test_ncap_terminal_grid_lists_every_selected_scenario():
    result = invoke("ncap", "--protocol", "2023", "--scenario", "CPRA")
    assert result.exit_code == 0, result.output
    for code in ("CPRA-Cm", "CPRA-Cs"):
        assert code in result.stdout
    assert "Total" in result.stdout
    assert "tests, planner fsm, V2X off" in result.stdout


@pytest.mark.parametrize(
    ("args", "names"),
    [
        (["--scenario", "XYZ-99"], ["--scenario", "XYZ-99"]),
        (["--planner", "nonsense"], ["--planner", "nonsense"]),
        (["--planner", "no_such_module:Planner"], ["--planner"]),
        (["--scenario", ""], ["--scenario"]),
    ],
)
def test_ncap_bad_options_are_user_errors(args, names):
    assert_user_error(invoke("ncap", *args), *names)


def test_ncap_out_that_is_a_file_is_a_user_error(tmp_path):
    target = tmp_path / "taken"
    target.write_text("keep me")
    assert_user_error(invoke("ncap", "--protocol", "2023", "--scenario", "CPTAns", "--out", target), "--out", "taken")
    assert target.read_text() == "keep me"


def test_out_targets_are_checked_before_the_run_and_written_all_or_none(tmp_path):
    (tmp_path / "scorecard.png").mkdir()
    result = invoke(
        "ncap", "--protocol", "2023", "--scenario", "CPTAns", "--out", tmp_path, "--force"
    )  # not empty: --force
    assert_user_error(result, "--out", "scorecard.png")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scorecard.png"]  # nothing else written


def test_scenario_selection_is_a_case_insensitive_prefix():
    assert {t.spec.code for t in select(protocol="2023", codes=["cmrs"])} == {"CMRs", "CMRs-FCW"}
    assert {t.spec.code for t in select(protocol="2023", codes=["CPTA"])} == {"CPTAfs", "CPTAfo", "CPTAns", "CPTAno"}
    assert {t.spec.code for t in select(protocol="2023", codes=["CPNA-25"])} == {"CPNA-25"}


def test_list_shows_every_entry_and_its_flags():
    result = invoke("list", "--protocol", "2023", "--json")
    assert result.exit_code == 0, result.output
    rows = json.loads(result.stdout)
    assert [r["code"] for r in rows] == [s.code for s in SCENARIOS]
    by_code = {r["code"]: r for r in rows}
    assert by_code["CENA-50"]["extension"] is True
    assert by_code["CPNA-25"]["extension"] is False
    assert by_code["CBTAfs"]["unverified"]
    assert by_code["CPNCO-50"]["obstruction"] == "CPNCO"
    assert by_code["CPNA-25"]["vut_speeds_kph"] == [10.0 + 5 * i for i in range(11)]
    assert by_code["CPRA-Cs"]["targets"] == ["EPTa", "EPTc"]
    assert by_code["CPRA-Cs"]["impact_locations_pct"] == [25, 50, 75]
    assert by_code["CBTAns"]["impact_side"] == "right"
    assert by_code["CPNA-25"]["geometry"]["lateral_offset_m"] == 4.0
    assert by_code["CMRb"]["target_speeds_kph"] == "vut"
    assert any(flag.startswith("EBTa: ") for flag in by_code["CBLA-50"]["unverified"])  # dummy flags too
    text = invoke("list", "--protocol", "2023")
    assert text.exit_code == 0
    assert "CPNCO-50" in text.stdout
    assert "side impact at 50 % of the VUT length" in " ".join(text.stdout.split())
