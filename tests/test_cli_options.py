"""The options every `vrusim` command shares, read the same way everywhere; bundled examples by name; help text
without `<bool>`; tables that fit 80 columns; the command-line package's shape."""

from __future__ import annotations

import io
import json
import shutil
import tomllib
from pathlib import Path

import pytest
import yaml
from rich.table import Table
from typer.testing import CliRunner

from cli_helpers import assert_user_error, invoke
from vrusim.cli.app import COMMANDS, app

REPO_ROOT = Path(__file__).resolve().parents[1]
PEDESTRIAN = REPO_ROOT / "scenarios" / "paper" / "pedestrian_crossing.yaml"
MONTE_CARLO = "example:pedestrian-monte-carlo"
BUNDLED = [
    "paper:pedestrian",
    "paper:escooter",
    "paper:motorcyclist",
    "example:escooter-stationary",
    "example:right-turn-cyclist",
    MONTE_CARLO,
]


def _invoke_at(columns: int, *args):
    """`vrusim ARGS...` with the terminal `columns` wide."""
    runner = CliRunner()
    return runner.invoke(app, [str(a) for a in args], env={"COLUMNS": str(columns)}, catch_exceptions=False)


def _options(command: str) -> set[str]:
    import typer.main

    click_command = typer.main.get_command(app).commands[command]
    return {name for param in click_command.params for name in param.opts}


# ----------------------------------------------------------------------------------------------- the app


def test_console_script_and_python_m_use_the_app():
    scripts = tomllib.loads((REPO_ROOT / "pyproject.toml").read_text())["project"]["scripts"]
    assert scripts == {"vrusim": "vrusim.cli.app:main"}
    main_module = (REPO_ROOT / "src" / "vrusim" / "__main__.py").read_text()
    assert "from vrusim.cli.app import main" in main_module


def test_one_module_per_command():
    """Each command lives in its own module of vrusim.cli (`ncap` shares one with its catalogue `list`; `import`, a
    Python keyword, is `importing`)."""
    modules = {name: command.__module__ for name, command in COMMANDS.items()}
    assert modules["list"] == modules["ncap"] == "vrusim.cli.ncap"
    assert modules.pop("import") == "vrusim.cli.importing"
    others = {name: module for name, module in modules.items() if name != "list"}
    assert others == {name: f"vrusim.cli.{name}" for name in others}


@pytest.mark.parametrize("command", [None, *COMMANDS])
def test_help_shows_no_bool_type(command):
    result = _invoke_at(200, *([command] if command else []), "--help")
    assert result.exit_code == 0, result.output
    assert "--help" in result.output
    assert "<bool>" not in result.output


@pytest.mark.parametrize("command", sorted(set(COMMANDS)))
def test_every_command_prints_json_on_request(command):
    assert "--json" in _options(command)


@pytest.mark.parametrize(
    ("command", "options"),
    [
        ("run", {"--planner", "--v2x", "--seed", "--json"}),
        ("compare", {"--planner", "--v2x", "--seed", "--json"}),
        ("ncap", {"--planner", "--v2x", "--out", "--force", "--json"}),
        ("report", {"--planner", "--v2x", "--seed", "--out", "--json"}),
        ("sweep", {"--seed", "--out", "--force", "--json"}),
        ("export", {"--out", "--force", "--json"}),
    ],
)
def test_commands_share_the_option_names(command, options):
    assert options <= _options(command)


# ----------------------------------------------------------------------------------------------- --planner


def test_planner_is_repeatable_and_a_comma_list():
    from vrusim.cli.options import planner_names

    assert planner_names(["fsm,aeb", " predictive ", "fsm"]) == ["fsm", "aeb", "predictive"]
    assert planner_names(None) == []


@pytest.mark.parametrize(
    "args",
    [
        ["run", PEDESTRIAN],
        ["ncap", "--protocol", "2023", "--scenario", "CPTAns"],
        ["report", PEDESTRIAN, "--out", "unused.html"],
        ["compare", PEDESTRIAN],
    ],
    ids=["run", "ncap", "report", "compare"],
)
def test_an_unknown_planner_is_named_the_same_way_everywhere(args):
    assert_user_error(invoke(*args, "--planner", "fsm,bogus"), "--planner", "bogus")
    assert_user_error(invoke(*args, "--planner", " , "), "--planner")


@pytest.mark.parametrize(
    "args",
    [
        ["run", PEDESTRIAN],
        ["ncap", "--protocol", "2023", "--scenario", "CPTAns"],
        ["report", PEDESTRIAN, "--out", "unused.html"],
    ],
    ids=["run", "ncap", "report"],
)
def test_commands_that_run_one_planner_refuse_several(args):
    for planners in (["--planner", "fsm,aeb"], ["--planner", "fsm", "--planner", "aeb"]):
        assert_user_error(invoke(*args, *planners), "--planner", "fsm, aeb", "vrusim compare")


def test_compare_takes_planner_twice_or_as_a_list_and_the_old_planners():
    test_id = "CPNA-25/20kph/day"
    rows = [
        json.loads(invoke("compare", test_id, *args, "--v2x", "off", "--json").stdout)
        for args in (["--planner", "fsm", "--planner", "aeb"], ["--planner", "fsm,aeb"], ["--planners", "fsm,aeb"])
    ]
    assert [r["planner"] for r in rows[0]] == ["fsm", "aeb"]
    assert rows[0] == rows[1] == rows[2]
    deprecated = invoke("compare", test_id, "--planners", "fsm", "--v2x", "off", "--json")
    assert "--planners is deprecated" in deprecated.stderr
    assert "--planners" not in invoke("compare", "--help").output  # hidden


# ----------------------------------------------------------------------------------------------- run


def test_run_takes_planner_and_seed():
    from vrusim.engine.simulate import simulate
    from vrusim.metrics.summary import summary_rows
    from vrusim.sources import apply_planner_and_seed, scenario_of

    result = invoke("run", PEDESTRIAN, "--planner", "aeb", "--seed", "7", "--json")
    assert result.exit_code == 0, result.output
    row = json.loads(result.stdout)
    assert row["planner"] == "aeb"
    scenario = apply_planner_and_seed(scenario_of(str(PEDESTRIAN)), "aeb", 7)
    assert (scenario.planner.name, scenario.planner.params, scenario.sim.seed) == ("aeb", {}, 7)
    assert row == summary_rows(simulate([scenario]))[0]
    default = json.loads(invoke("run", PEDESTRIAN, "--json").stdout)
    assert default["planner"] == "fsm" and default != row


def test_run_planner_on_a_catalogue_test_is_what_ncap_runs():
    from vrusim.metrics.summary import summary_rows
    from vrusim.ncap.grid import run_tests
    from vrusim.sources import single_test

    test_id = "CPNA-25/20kph/day"
    row = json.loads(invoke("run", test_id, "--planner", "aeb", "--v2x", "on", "--json").stdout)
    expected = summary_rows(run_tests([single_test(test_id)], planner="aeb", v2x=True).run)[0]
    assert row == expected


@pytest.mark.parametrize(
    "args",
    [["run", PEDESTRIAN], ["compare", PEDESTRIAN], ["report", PEDESTRIAN, "--out", "unused.html"], ["sweep", "x"]],
    ids=["run", "compare", "report", "sweep"],
)
def test_a_bad_seed_is_named(args):
    for seed in ("-1", str(2**63), "seven"):
        result = invoke(*args, "--seed", seed)
        assert result.exit_code == 2 and "--seed" in result.output, result.output


@pytest.mark.parametrize(
    "args",
    [
        ["run", PEDESTRIAN],
        ["ncap", "--protocol", "2023", "--scenario", "CPTAns"],
        ["report", PEDESTRIAN, "--out", "unused.html"],
    ],
    ids=["run", "ncap", "report"],
)
def test_a_bad_v2x_switch_is_named(args):
    result = invoke(*args, "--v2x", "maybe")
    assert result.exit_code == 2 and "--v2x" in result.output, result.output


def test_compare_v2x_on_is_the_scenarios_own_channel():
    rows = json.loads(invoke("compare", PEDESTRIAN, "--v2x", "off,on", "--json").stdout)
    by_v2x = {row["v2x"]: row for row in rows}
    for switch in ("off", "on"):
        run = json.loads(invoke("run", PEDESTRIAN, "--v2x", switch, "--json").stdout)
        assert by_v2x[switch]["collisions"] == int(run["collided"])
        assert by_v2x[switch]["safety"] == round(run["safety"], 4)


# ----------------------------------------------------------------------------------------------- --out, --force


def _sweep_spec(folder: Path) -> Path:
    spec = {
        "name": "tiny",
        "base": str(PEDESTRIAN),
        "parameters": {"ego.cruise_speed_mps": [14.0, 15.0]},
        "samples": 1,
        "batch_size": 2,
    }
    path = folder / "spec.yaml"
    path.write_text(yaml.safe_dump(spec))
    return path


def _writers(tmp_path: Path) -> dict[str, list]:
    """Per command that writes a folder: its arguments before --out."""
    return {
        "ncap": ["ncap", "--protocol", "2023", "--scenario", "CPTAns"],
        "export": ["export", "paper:pedestrian", "--format", "openscenario"],
        "sweep": ["sweep", _sweep_spec(tmp_path), "--quiet", "--workers", "1"],
    }


@pytest.mark.parametrize("command", ["ncap", "export", "sweep"])
def test_out_refuses_a_folder_that_is_not_empty_without_force(tmp_path, command):
    args = _writers(tmp_path)[command]
    out = tmp_path / "out"
    assert invoke(*args, "--out", out).exit_code == 0
    first = {path.name: path.stat().st_mtime_ns for path in out.iterdir()}
    assert first
    assert_user_error(invoke(*args, "--out", out), "--out", "--force")
    assert {path.name: path.stat().st_mtime_ns for path in out.iterdir()} == first  # nothing written
    again = invoke(*args, "--out", out, "--force")
    assert again.exit_code == 0, again.output
    assert set(first) <= {path.name for path in out.iterdir()}
    assert all(path.stat().st_mtime_ns >= first[path.name] for path in out.iterdir() if path.name in first)


def test_out_that_is_a_file_is_refused_everywhere(tmp_path):
    taken = tmp_path / "taken"
    taken.write_text("keep")
    for args in _writers(tmp_path).values():
        assert_user_error(invoke(*args, "--out", taken, "--force"), "--out")
    assert taken.read_text() == "keep"


def test_sweep_force_replaces_only_a_previous_sweep(tmp_path):
    spec = _sweep_spec(tmp_path)
    other = tmp_path / "other"
    other.mkdir()
    (other / "notes.txt").write_text("mine")
    assert_user_error(invoke("sweep", spec, "--out", other, "--force"), "--out", "no manifest.json")
    assert [p.name for p in other.iterdir()] == ["notes.txt"]
    out = tmp_path / "out"
    assert invoke("sweep", spec, "--out", out, "--quiet", "--workers", "1").exit_code == 0
    (out / "chunks" / "chunk-000099.parquet").write_text("stale")
    result = invoke("sweep", spec, "--out", out, "--force", "--seed", "5", "--json", "--workers", "1")
    assert result.exit_code == 0, result.output
    assert not (out / "chunks" / "chunk-000099.parquet").exists()
    assert json.loads((out / "manifest.json").read_text())["seed"] == 5
    assert_user_error(invoke("sweep", spec, "--out", out, "--force", "--resume"), "--force", "--resume")
    assert_user_error(invoke("sweep", "--out", out, "--resume", "--seed", "1"), "--seed")


# ----------------------------------------------------------------------------------------------- bundled examples


def test_examples_lists_every_bundled_name():
    result = invoke("examples", "--json")
    assert result.exit_code == 0, result.output
    entries = json.loads(result.stdout)
    assert [e["name"] for e in entries] == BUNDLED
    assert all(Path(e["path"]).is_file() and e["description"] for e in entries)
    assert {e["kind"] for e in entries} == {"scenario", "sweep"}
    text = _invoke_at(80, "examples")
    assert all(name in text.stdout for name in BUNDLED)


def test_every_bundled_scenario_loads_by_name():
    from vrusim.scenario.loading import load_scenario
    from vrusim.sources import bundled_scenarios, scenario_of

    for entry in bundled_scenarios():
        assert scenario_of(entry.name) == load_scenario(entry.path)


def test_run_by_bundled_name_equals_run_of_the_file():
    by_name = invoke("run", "paper:pedestrian", "--v2x", "on", "--json")
    assert by_name.exit_code == 0, by_name.output
    assert json.loads(by_name.stdout) == json.loads(invoke("run", PEDESTRIAN, "--v2x", "on", "--json").stdout)


def test_an_unknown_bundled_name_suggests_close_ones():
    assert_user_error(invoke("run", "paper:pedestrain"), "SOURCE", "paper:pedestrian", "vrusim examples")
    assert_user_error(invoke("sweep", "example:monte-carlo", "--dry-run"), "SPEC", MONTE_CARLO)


def test_sweep_dry_run_of_a_bundled_spec():
    result = invoke("sweep", MONTE_CARLO, "--dry-run", "--json")
    assert result.exit_code == 0, result.output
    plan = json.loads(result.stdout)
    assert plan["name"] == "pedestrian-monte-carlo" and plan["variants"] == 100_000
    assert Path(plan["base"]).resolve() == PEDESTRIAN.resolve()


def test_bundled_files_resolve_inside_an_installed_wheel(tmp_path, monkeypatch):
    """The wheel holds scenarios/ and sweeps/ side by side (pyproject.toml), so a bundled spec's relative base
    resolves inside the installed package."""
    import vrusim.io.bundled as bundled_io
    from vrusim.sources import sweep_spec_path
    from vrusim.sweep.spec import load_spec

    include = tomllib.loads((REPO_ROOT / "pyproject.toml").read_text())["tool"]["hatch"]["build"]["targets"]
    targets = include["wheel"]["force-include"]
    assert targets == {"scenarios": "vrusim/_data/scenarios", "sweeps": "vrusim/_data/sweeps"}
    for folder, target in targets.items():
        shutil.copytree(REPO_ROOT / folder, tmp_path / target)
    monkeypatch.setattr(bundled_io, "_package_folder", lambda: tmp_path / "vrusim")
    spec_file = sweep_spec_path(MONTE_CARLO)
    assert spec_file.is_relative_to(tmp_path)
    base = load_spec(spec_file).base_file.resolve()
    assert base == (tmp_path / "vrusim/_data/scenarios/paper/pedestrian_crossing.yaml").resolve()
    assert base.is_file()
    result = invoke("run", "paper:escooter", "--json")
    assert result.exit_code == 0, result.output


def test_dry_run_counts_catalogue_tests_once(tmp_path):
    spec = {
        "name": "catalogue",
        "catalogue": {"scenarios": ["CPNA-25"], "protocol": "2023"},
        "parameters": {"ego.cruise_speed_mps": [5.0, 6.0]},
        "samples": 3,
    }
    path = tmp_path / "spec.yaml"
    path.write_text(yaml.safe_dump(spec))
    plan = json.loads(invoke("sweep", path, "--dry-run", "--json").stdout)
    assert plan["variants"] == plan["tests"] * 2 * 3 == plan["grid_points"] * plan["samples"]
    text = " ".join(invoke("sweep", path, "--dry-run").stdout.split())
    factors = f"{plan['tests']} catalogue tests × 2 parameter grid points × 3 samples"
    assert f"{plan['variants']} variants ({factors})" in text


# ----------------------------------------------------------------------------------------------- 80 columns


def _assert_fits(text: str, headers: list[str], columns: int = 80) -> None:
    assert "…" not in text
    assert max(len(line) for line in text.splitlines()) <= columns
    for header in headers:
        for word in header.split():
            assert word in text, word


def test_list_at_80_columns_shows_every_header_and_code():
    from vrusim.ncap.editions.v2023 import SCENARIOS

    result = _invoke_at(80, "list", "--protocol", "2023")
    assert result.exit_code == 0, result.output
    headers = ["Code", "Function", "Target km/h", "VUT km/h", "Impact at %", "Light", "Tests", "Geometry"]
    _assert_fits(result.stdout, [*headers, "Obstruction", "Flags / unverified"])
    assert all(spec.code in result.stdout for spec in SCENARIOS)


def test_compare_and_run_at_80_columns():
    compared = _invoke_at(80, "compare", "CPNA-25/20kph/day", "--planner", "fsm,predictive", "--v2x", "off,typical")
    assert compared.exit_code == 0, compared.output
    headers = ["Planner", "V2X", "Collisions", "P 95 %", "Impact m/s", "min TTC s", "Sensor s", "Safety", "Efficiency"]
    _assert_fits(compared.stdout, [*headers, "Comfort", "predictive", "typical"])
    ran = _invoke_at(80, "run", PEDESTRIAN)
    _assert_fits(ran.stdout, ["Outcome", "Travel time", "Comfort score"])


def test_paper_tables_at_80_columns(monkeypatch):
    import copy

    import vrusim.paper.cases as cases

    result = cases.reproduce()
    monkeypatch.setattr(cases, "reproduce", lambda: copy.deepcopy(result))
    text = _invoke_at(80, "paper").stdout
    headers = ["Case", "V2X", "Outcome paper", "Outcome ours", "Safety", "Efficiency", "Comfort", "±0.05"]
    _assert_fits(text, [*headers, "Event", "Paper (s)", "Ours (s)", "Δ (s)", "Motorcyclist", "collision"])


def test_fit_wraps_prose_and_keeps_codes_whole():
    """Rich alone shrinks every column evenly and cuts the codes; `fit_table` wraps the prose column instead."""
    from rich.console import Console

    from vrusim.cli.fit import fit_table

    def table() -> Table:
        made = Table("Code", "Notes", "More notes")
        for index in range(3):
            made.add_row(f"CBNAO-5{index}", "a long note that has to wrap " * 3, "and another one " * 5)
        return made

    def render(made: Table) -> str:
        console = Console(width=30, record=True, file=io.StringIO())
        console.print(made)
        return console.export_text()

    assert "CBNAO-50" not in render(table())  # what Rich does alone
    fitted = render(fit_table(table(), Console(width=30)))
    assert all(f"CBNAO-5{index}" in fitted for index in range(3)) and "…" not in fitted
    assert max(len(line) for line in fitted.splitlines()) <= 30


def test_the_v2x_switch_names_the_option_of_its_caller(tmp_path):
    """`apply_v2x_switch` serves the command line (`--v2x`) and Python callers (`v2x`) alike."""
    from vrusim.errors import UserInputError
    from vrusim.sources import scenario_of

    data = yaml.safe_load(PEDESTRIAN.read_text())
    del data["v2x"]
    path = tmp_path / "no_rsu.yaml"
    path.write_text(yaml.safe_dump(data))
    with pytest.raises(UserInputError, match=r"no_rsu\.yaml with v2x on: invalid scenario"):
        scenario_of(path, v2x=True)
    with pytest.raises(UserInputError, match=r"no_rsu\.yaml with --v2x on"):
        scenario_of(str(path), v2x=True, option="--v2x")
    assert scenario_of(str(path), v2x=False).v2x.enabled is False
