"""`vrusim ncap --protocol 2026`: the JSON equals the API's, outputs and predictions are written, and every bad
2026 option is one clear error (exit 2) before anything runs or is written."""

from __future__ import annotations

import json
import subprocess
import sys

import pyarrow.parquet as pq
import pytest

import vrusim
from cli_helpers import assert_user_error, invoke
from vrusim.errors import UserInputError

openpyxl = pytest.importorskip("openpyxl")


@pytest.fixture(scope="module")
def cpna_json():
    result = invoke("ncap", "--scenario", "CPNA", "--planner", "aeb", "--json")
    assert result.exit_code == 0, result.output
    return json.loads(result.stdout)


def test_2026_is_the_default_and_the_json_equals_the_api(cpna_json):
    assert cpna_json["protocol"] == "2026"
    assert len(cpna_json["assessment"]["cells"]) == 30  # 10..60 km/h x 5 impact locations, day
    api = vrusim.euro_ncap("CPNA", planner="aeb")
    assert json.loads(json.dumps(api.to_dict(), allow_nan=False)) == cpna_json
    assert cpna_json["assessment"]["sub_elements"] == pytest.approx(api.sub_elements)


def test_out_writes_results_scorecard_and_verification_and_forgets_a_stale_one(tmp_path):
    folder = tmp_path / "out"
    result = invoke("ncap", "--scenario", "CPNA", "--planner", "aeb", "--verify", "50", "--out", folder)
    assert result.exit_code == 0, result.output
    rows = pq.read_table(folder / "results.parquet").to_pylist()
    assert len(rows) == 30 and {r["protocol"] for r in rows} == {"2026"}
    assert all(r["colour"] in ("green", "yellow", "orange", "brown", "red") for r in rows)
    checked = [r["verification_pass_probability"] for r in rows if r["verification_pass_probability"] is not None]
    assert checked and all(0.0 <= p <= 1.0 for p in checked)
    verification = json.loads((folder / "verification.json").read_text())
    assert verification["n_draws"] == 50 and "CPNA day" in verification["scenarios"]
    assert (folder / "scorecard.png").stat().st_size > 10_000
    report = tmp_path / "r.html"
    assert invoke("report", folder, "--out", report).exit_code == 0
    assert "CPNA day" in report.read_text()
    again = invoke("ncap", "--scenario", "CPNA", "--planner", "aeb", "--out", folder, "--force")
    assert again.exit_code == 0, again.output
    assert not (folder / "verification.json").exists()


def test_predictions_fill_the_official_template_with_the_simulated_colours(tmp_path, cpna_json):
    path = tmp_path / "pred.xlsx"
    result = invoke("ncap", "--scenario", "CPNA", "--planner", "aeb", "--predictions", path)
    assert result.exit_code == 0, result.output
    book = openpyxl.load_workbook(path)
    words = {
        str(cell.value).lower()
        for row in book["FC - Ped & Cyc pred."].iter_rows()
        for cell in row
        if str(cell.value).lower() in ("green", "yellow", "orange", "brown", "red")
    }
    assert words == {c["colour"] for c in cpna_json["assessment"]["cells"]}


def test_predictions_may_go_into_the_out_folder_being_created(tmp_path, monkeypatch):
    """`--out o --predictions o/p.xlsx` was refused (folder o does not exist) though ncap creates --out; and when
    writing the predictions is refused, nothing is left behind."""
    from vrusim.cli import ncap2026

    runs: list = []
    run_once = ncap2026.run_2026
    monkeypatch.setattr(
        ncap2026, "run_2026", lambda *args: runs[0] if runs else runs.append(run_once(*args)) or runs[0]
    )
    folder = tmp_path / "o"
    result = invoke(
        "ncap", "--scenario", "CPNA", "--planner", "aeb", "--out", folder, "--predictions", folder / "p.xlsx"
    )
    assert result.exit_code == 0, result.output
    assert {p.name for p in folder.iterdir()} == {"p.xlsx", "results.csv", "results.parquet", "scorecard.png"}

    def refuse(self, path):
        raise UserInputError("refused")

    monkeypatch.setattr("vrusim.ncap.rated2026.Rated2026.write_predictions", refuse)  # the run above, reused
    other = tmp_path / "other"
    result = invoke(
        "ncap", "--scenario", "CPNA", "--planner", "aeb", "--out", other, "--predictions", other / "sub" / "p.xlsx"
    )
    assert_user_error(result, "refused")
    assert not other.exists()


@pytest.mark.parametrize(
    ("args", "names"),
    [
        (["--out", "{tmp}/o", "--predictions", "{tmp}/o/p.csv"], ["--predictions", ".xlsx"]),
        (["--predictions", "{tmp}/out/../missing/p.xlsx"], ["--predictions", "does not exist"]),
        (["--protocol", "2023", "--predictions", "{tmp}/p.xlsx"], ["--predictions", "--protocol 2026"]),
        (["--protocol", "2023", "--verify", "10"], ["--verify", "--protocol 2026"]),
        (["--verify", "-1"], ["--verify", "-1"]),
        (["--predictions", "{tmp}/missing/p.xlsx"], ["--predictions", "does not exist"]),
        (["--predictions", "{tmp}/p.csv"], ["--predictions", ".xlsx"]),
        (["--scenario", "CPNA-25"], ["--scenario", "CPNA-25", "2026"]),
    ],
)
def test_bad_2026_options_are_refused_before_anything_runs(tmp_path, args, names):
    argv = [arg.replace("{tmp}", str(tmp_path)) for arg in args]
    out = tmp_path / "out"
    assert_user_error(invoke("ncap", *argv, "--out", out), *names)
    assert not out.exists()


def test_a_missing_calculator_extra_is_one_clear_error(tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "euroncap_rating_2026", None)  # import fails as if not installed
    result = invoke("ncap", "--scenario", "CPNA", "--predictions", tmp_path / "p.xlsx")
    assert_user_error(result, "ncap2026", "euroncap-rating-2026")
    assert not (tmp_path / "p.xlsx").exists()


def test_list_shows_the_2026_edition_with_its_ranges():
    rows = json.loads(invoke("list", "--json").stdout)
    codes = {row["code"] for row in rows}
    assert {"CPNA", "CBDA", "CMCscp", "CPMFC"} <= codes
    text = invoke("list").stdout
    assert "2026" in text or "Crash Avoidance" in text


def test_the_terminal_scorecard_does_not_import_matplotlib():
    """Start-up time: the terminal path of `vrusim ncap` (both editions) never imports matplotlib (~0.3 s); only
    --out (scorecard.png) and --report draw figures."""
    code = (
        "import sys\n"
        "from vrusim.cli.app import main\n"
        "for protocol in ('2026', '2023'):\n"
        "    try:\n"
        "        main(['ncap', '--protocol', protocol, '--scenario', 'CPNA', '--planner', 'none'])\n"
        "    except SystemExit as exit:\n"
        "        assert not exit.code, exit.code\n"
        "print('matplotlib' in sys.modules)\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, check=True)
    assert "CPNA" in done.stdout and "points" in done.stdout.lower()
    assert done.stdout.strip().splitlines()[-1] == "False"
