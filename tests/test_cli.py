"""The `vrusim` command line: run, paper, --version, trace files and user-error handling (exit code 2)."""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
from pathlib import Path

import pyarrow.csv as pa_csv
import pyarrow.parquet as pq
import pytest
import yaml

from cli_helpers import assert_user_error, invoke
from vrusim.cli.app import main
from vrusim.errors import UserInputError
from vrusim.version import __version__

REPO_ROOT = Path(__file__).resolve().parents[1]
PEDESTRIAN = REPO_ROOT / "scenarios" / "paper" / "pedestrian_crossing.yaml"


@pytest.fixture(scope="module")
def paper_json() -> dict:
    result = invoke("paper", "--json")
    assert result.exit_code == 0, result.output
    return json.loads(result.stdout)


# ---------------------------------------------------------------------------------------------- run
# A V2X-on run of the pedestrian case takes ~1 s (V2X off ~0.4 s): each is run as few times as possible.


@pytest.fixture(scope="module")
def v2x_on_csv(tmp_path_factory) -> tuple[dict, Path]:
    """`run --v2x on --json --trace t.csv`: the summary row and the trace file."""
    out = tmp_path_factory.mktemp("csv") / "trace.csv"
    result = invoke("run", PEDESTRIAN, "--v2x", "on", "--json", "--trace", out)
    assert result.exit_code == 0, result.output
    assert [p.name for p in out.parent.iterdir()] == [out.name]  # no temp file left behind
    return json.loads(result.stdout), out


def test_run_v2x_off_collides():
    result = invoke("run", PEDESTRIAN, "--v2x", "off")
    assert result.exit_code == 0, result.output
    assert "COLLISION" in result.stdout
    assert "V2X off" in result.stdout
    for label in ("Contact time", "First sensor detection", "Planner transitions", "Min TTC", "Safety score"):
        assert label in result.stdout
    assert "emergency_brake" in result.stdout


def test_run_json_is_one_document():
    result = invoke("run", PEDESTRIAN, "--v2x", "OFF", "--json")  # option values are case-insensitive
    assert result.exit_code == 0, result.output
    row = json.loads(result.stdout)  # the whole of stdout is one JSON document
    for key in ("outcome", "safety", "efficiency", "comfort", "contact_time_s"):
        assert key in row
    assert row["outcome"] == "collision"
    assert row["contact_time_s"] == pytest.approx(5.0, abs=0.3)
    assert row["v2x"] is False
    assert result.stderr == ""


def test_run_takes_one_catalogue_test_id():
    """`vrusim run TEST-ID` builds the test as `vrusim ncap` does (FSM; --v2x on adds its roadside unit)."""
    from vrusim.metrics.summary import summary_rows
    from vrusim.ncap.grid import run_tests, select

    test_id = "CPNA-25/20kph/day"
    for switch, v2x in (("off", False), ("on", True)):
        result = invoke("run", test_id, "--v2x", switch, "--json")
        assert result.exit_code == 0, result.output
        row = json.loads(result.stdout)
        assert (row["scenario"], row["v2x"], row["planner"]) == (test_id, v2x, "fsm")
        test = next(t for t in select(protocol="2023", codes=["CPNA-25"], night=False) if t.test_id == test_id)
        expected = summary_rows(run_tests([test], v2x=v2x).run)[0]
        assert (row["outcome"], row["min_clearance_m"]) == (expected["outcome"], expected["min_clearance_m"])


@pytest.mark.parametrize(
    ("source", "message"),
    [
        ("CPNA-25", "SOURCE: 'CPNA-25' selects"),  # a code: many tests
        ("CPNX-25/20kph/day", "did you mean CPNA-25/20kph/day"),
        ("missing.yaml", "missing.yaml: no such scenario file"),
    ],
)
def test_run_source_errors(source, message):
    assert_user_error(invoke("run", source), message)


def test_run_json_pipes_into_json_tool():
    command = f"{sys.executable} -m vrusim run {PEDESTRIAN} --v2x off --json | {sys.executable} -m json.tool"
    done = subprocess.run(command, shell=True, capture_output=True, text=True, check=False)
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout)["outcome"] == "collision"


def _steps(row: dict) -> int:
    """Number of simulated steps of a run, from its summary (dt = 0.01 s in the paper files)."""
    return round(row["end_time_s"] / 0.01)


def _check_trace_table(table, steps: int) -> None:
    assert table.num_rows == steps
    expected = [
        "t_s",
        "ego_x_m",
        "ego_y_m",
        "ego_heading_deg",
        "ego_speed_mps",
        "ego_accel_mps2",
        "ego_command_mps2",
        "ego_curvature_per_m",
        "ego_station_m",
        "planner_mode",
        "clearance_m",
        "ttc_s",
        "vru0_x_m",
        "vru0_y_m",
        "vru0_speed_mps",
        "vru0_detected",
        "vru0_source",
        "vru0_v2x_age_s",
    ]
    assert table.column_names == expected
    data = table.to_pydict()
    for name, values in data.items():
        for value in values:
            assert not (isinstance(value, float) and math.isnan(value)), name
    modes = set(data["planner_mode"])
    assert modes <= {"cruise", "pre_slow", "emergency_brake", "follow"}
    assert {"cruise", "pre_slow", "emergency_brake"} <= modes
    assert None in data["ttc_s"]  # infinite TTC is written as null, never inf/NaN
    assert all(math.isfinite(v) for v in data["ttc_s"] if v is not None)
    assert set(data["vru0_source"]) <= {0, 1, 2, 3}
    assert set(data["vru0_source"]) & {2, 3}  # V2X on: some V2X-sourced steps
    assert set(data["vru0_detected"]) == {False, True}
    times = data["t_s"]
    assert times == sorted(times)
    assert times[0] == pytest.approx(0.01)
    assert times[-1] == pytest.approx(steps * 0.01)


def test_run_v2x_on_avoids_and_writes_parquet(tmp_path, v2x_on_csv):
    out = tmp_path / "trace.parquet"
    result = invoke("run", PEDESTRIAN, "--v2x", "on", "--trace", out)
    assert result.exit_code == 0, result.output
    assert "avoided" in result.stdout
    assert "COLLISION" not in result.stdout
    assert "V2X on" in result.stdout
    assert "Trace written" in result.stdout
    assert [p.name for p in tmp_path.iterdir()] == [out.name]  # no temp file left behind
    row, _ = v2x_on_csv
    _check_trace_table(pq.read_table(out), _steps(row))


def test_run_json_with_csv_trace(v2x_on_csv):
    row, out = v2x_on_csv
    assert row["outcome"] == "avoided" and row["v2x"] is True
    _check_trace_table(pa_csv.read_csv(out), _steps(row))


def test_run_trace_bad_suffix(tmp_path):
    out = tmp_path / "trace.txt"
    result = invoke("run", PEDESTRIAN, "--trace", out)
    assert_user_error(result, "--trace", ".csv")
    assert not out.exists()
    assert list(tmp_path.iterdir()) == []


def test_run_trace_missing_folder(tmp_path):
    out = tmp_path / "no" / "such" / "trace.csv"
    result = invoke("run", PEDESTRIAN, "--trace", out)
    assert_user_error(result, "--trace", str(out.parent))


def test_write_trace_failure_leaves_nothing(tmp_path, monkeypatch):
    import vrusim.engine.trace_file as trace_io
    from vrusim.engine.simulate import simulate
    from vrusim.scenario.loading import load_scenario

    run = simulate([load_scenario(PEDESTRIAN)], trace=True)
    out = tmp_path / "trace.parquet"
    out.write_text("previous contents")

    def broken(table, where):
        Path(where).write_bytes(b"half")
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(trace_io.pq, "write_table", broken)
    with pytest.raises(UserInputError, match="No space left"):
        trace_io.write_trace(run, out)
    assert out.read_text() == "previous contents"
    assert [p.name for p in tmp_path.iterdir()] == ["trace.parquet"]


def test_write_trace_needs_a_trace(tmp_path):
    from types import SimpleNamespace

    from vrusim.engine.trace_file import write_trace

    with pytest.raises(ValueError, match="trace=True"):
        write_trace(SimpleNamespace(trace=None), tmp_path / "unused.csv")
    assert list(tmp_path.iterdir()) == []


# ---------------------------------------------------------------------------------------------- paper


def test_paper_json(paper_json):
    assert len(paper_json["cases"]) == 6
    assert len(paper_json["events"]) == 7
    assert {(c["case"], c["v2x"]) for c in paper_json["cases"]} == {
        (key, v2x) for key in ("pedestrian", "escooter", "motorcyclist") for v2x in (False, True)
    }


def test_paper_tables(paper_json, monkeypatch):
    import copy

    import vrusim.paper.cases as catalog

    monkeypatch.setattr(catalog, "reproduce", lambda: copy.deepcopy(paper_json))  # reuse the fixture's run
    result = invoke("paper")
    assert result.exit_code == 0, result.output
    out = result.stdout
    assert "Table II" in out
    assert "Event times" in out
    assert "Pedestrian crossing" in out and "Motorcyclist crossing" in out
    assert "Matches:" in out and "/6 outcomes" in out and "/7 events" in out
    assert "/6 follow from a collision" in out and "/4 calibrated" in out and "/8 checked out of sample" in out


def test_match_counts(paper_json):
    from vrusim.paper.cases import match_counts

    counts = match_counts(paper_json)
    assert counts["outcomes"][1] == 6 and counts["events"][1] == 7
    assert (counts["collision"][1], counts["calibrated"][1], counts["out_of_sample"][1]) == (6, 4, 8)
    assert counts["outcomes"][0] == sum(c["outcome_matches"] for c in paper_json["cases"])


# ---------------------------------------------------------------------------------------------- user errors


def _write_yaml(tmp_path: Path, data: dict) -> Path:
    path = tmp_path / "scenario.yaml"
    path.write_text(yaml.safe_dump(data), encoding="utf-8")
    return path


def _pedestrian_data() -> dict:
    return yaml.safe_load(PEDESTRIAN.read_text(encoding="utf-8"))


def test_unknown_field(tmp_path):
    data = _pedestrian_data()
    data["ego"]["cruise_speeed_mps"] = 10.0
    result = invoke("run", _write_yaml(tmp_path, data))
    assert_user_error(result, "ego.cruise_speeed_mps", "unknown field")


def test_negative_vru_speed(tmp_path):
    data = _pedestrian_data()
    data["vrus"][0]["top_speed_mps"] = -1.8
    result = invoke("run", _write_yaml(tmp_path, data))
    assert_user_error(result, "vrus[0].top_speed_mps")


def test_missing_file(tmp_path):
    missing = tmp_path / "nope.yaml"
    assert_user_error(invoke("run", missing), "nope.yaml")


def test_bad_v2x_value():
    result = invoke("run", PEDESTRIAN, "--v2x", "maybe")
    assert_user_error(result, "--v2x")


def test_unknown_option():
    assert_user_error(invoke("run", PEDESTRIAN, "--bogus"), "--bogus")


@pytest.mark.parametrize(
    ("content", "expected"),
    [
        ("name: [unclosed\n  ego: {\n", "not valid YAML"),
        ("just some words\n", "mapping"),
        ("", "mapping"),
    ],
)
def test_not_yaml(tmp_path, content, expected):
    path = tmp_path / "notes.yaml"
    path.write_text(content, encoding="utf-8")
    assert_user_error(invoke("run", path), "notes.yaml", expected)


def test_binary_file(tmp_path):
    path = tmp_path / "blob.yaml"
    path.write_bytes(b"\xff\xfe\x00\x81binary")
    assert_user_error(invoke("run", path), "blob.yaml")


def test_v2x_on_without_rsu(tmp_path):
    data = _pedestrian_data()
    del data["v2x"]
    result = invoke("run", _write_yaml(tmp_path, data), "--v2x", "on")
    assert_user_error(result, "--v2x", "rsu")


def test_unexpected_errors_keep_their_traceback(monkeypatch):
    import vrusim.engine.simulate as engine

    def boom(*args, **kwargs):
        raise RuntimeError("a bug")

    monkeypatch.setattr(engine, "simulate", boom)
    with pytest.raises(RuntimeError, match="a bug"):
        invoke("run", PEDESTRIAN)


# ---------------------------------------------------------------------------------------------- entry points


def test_version():
    result = invoke("--version")
    assert result.exit_code == 0
    assert __version__ in result.stdout


def test_main_maps_user_errors_to_exit_2(monkeypatch, capsys):
    import vrusim.cli.app as cli

    def raising(*args, **kwargs):
        raise UserInputError("somewhere.field: bad")

    monkeypatch.setattr(cli, "app", raising)
    with pytest.raises(SystemExit) as exit_info:
        main(["run", "x.yaml"])
    assert exit_info.value.code == 2
    captured = capsys.readouterr()
    assert "somewhere.field: bad" in captured.err
    assert captured.out == ""


def _python_m(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONIOENCODING": "utf-8"}
    return subprocess.run(
        [sys.executable, "-m", "vrusim", *map(str, args)],
        capture_output=True,
        text=True,
        check=False,
        cwd=cwd,
        env=env,
    )


def test_python_m_version():
    done = _python_m("--version")
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == f"vrusim {__version__}"


@pytest.mark.parametrize(
    ("args", "names"),
    [
        (("run", PEDESTRIAN, "--v2x", "maybe"), ("--v2x",)),
        (("run", "definitely-missing.yaml"), ("definitely-missing.yaml",)),
        (("run", PEDESTRIAN, "--trace", "out.json"), ("--trace",)),
    ],
)
def test_python_m_user_errors(tmp_path, args, names):
    done = _python_m(*args, cwd=tmp_path)
    assert done.returncode == 2, done.stderr
    for name in names:
        assert name in done.stderr
    assert "Traceback" not in done.stderr
    assert done.stdout == ""
    assert list(tmp_path.iterdir()) == []
