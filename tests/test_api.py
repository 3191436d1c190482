"""The public Python API: `import vrusim` (lazy, no side effects), load, Scenario.replace, run, euro_ncap, sweeps,
the results tables, and the example notebook that tours them."""

from __future__ import annotations

import inspect
import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pyarrow as pa
import pytest

import vrusim
from cli_helpers import invoke
from vrusim.engine.simulate import simulate
from vrusim.engine.trace_file import trace_table
from vrusim.errors import UserInputError
from vrusim.metrics.summary import summary_rows
from vrusim.ncap.build import build_test
from vrusim.ncap.grid import select
from vrusim.scenario.loading import load_scenario
from vrusim.scenario.schema import Scenario

REPO_ROOT = Path(__file__).resolve().parents[1]
SRC = REPO_ROOT / "src"
PAPER = REPO_ROOT / "scenarios" / "paper"
BUNDLED = {
    "paper:pedestrian": PAPER / "pedestrian_crossing.yaml",
    "paper:escooter": PAPER / "escooter_leading.yaml",
    "paper:motorcyclist": PAPER / "motorcyclist_crossing.yaml",
    "example:right-turn-cyclist": REPO_ROOT / "scenarios" / "examples" / "right_turn_cyclist.yaml",
}


@pytest.fixture(scope="module")
def pedestrian() -> Scenario:
    return load_scenario(BUNDLED["paper:pedestrian"])


# ----------------------------------------------------------------------------------------------- import vrusim

_IMPORT_PROBE = """
import json, os, sys
before = dict(os.environ)
import vrusim
after_import = dict(os.environ)
loaded = sorted(m for m in sys.modules if m.startswith("vrusim"))
names = {name: type(getattr(vrusim, name)).__name__ for name in vrusim.__all__}
print(json.dumps({"import_changed_env": before != after_import, "loaded": loaded, "names": names,
                  "resolve_changed_env": dict(os.environ) != before}))
"""


def _files_under(*folders: Path) -> list[Path]:
    return [path for folder in folders for path in folder.rglob("*")]


def test_import_vrusim_changes_no_environment_and_writes_nothing(tmp_path):
    home, cache, cwd = tmp_path / "home", tmp_path / "cache", tmp_path / "cwd"
    for folder in (home, cache, cwd):
        folder.mkdir()
    env = {key: value for key, value in os.environ.items() if key not in ("NUMBA_CACHE_DIR", "PYTHONDONTWRITEBYTECODE")}
    env |= {"HOME": str(home), "XDG_CACHE_HOME": str(cache), "PYTHONPATH": str(SRC), "PYTHONDONTWRITEBYTECODE": "1"}
    probe = "import vrusim, os, sys; print(sorted(m for m in sys.modules if m.startswith('vrusim')))"
    done = subprocess.run([sys.executable, "-c", probe], env=env, cwd=cwd, capture_output=True, text=True, check=True)
    assert done.stdout.strip() == "['vrusim', 'vrusim.version']"  # the API is not imported yet
    assert _files_under(home, cache, cwd) == []  # nothing written (bytecode caching is Python's, switched off)

    done = subprocess.run(
        [sys.executable, "-c", _IMPORT_PROBE], env=env, cwd=cwd, capture_output=True, text=True, check=True
    )
    report = json.loads(done.stdout)
    assert report["import_changed_env"] is False
    assert report["resolve_changed_env"] is False  # the API's imports (numba's cache setting included) neither
    assert report["names"] == {
        "CompileReport": "type",
        "Metric": "type",
        "NcapResults": "type",
        "NcapResults2026": "type",
        "Results": "type",
        "Scenario": "ModelMetaclass",
        "SweepFolder": "type",
        "UserInputError": "type",
        "__version__": "str",
        "compile_kernels": "function",
        "euro_ncap": "function",
        "load": "function",
        "open_sweep": "function",
        "run": "function",
        "register_loss_model": "function",
        "register_metric": "function",
        "register_vru_motion": "function",
        "run_sweep": "function",
        "unregister_loss_model": "function",
        "unregister_metric": "function",
        "unregister_vru_motion": "function",
    }


def test_public_names_are_listed_documented_and_resolve():
    assert dir(vrusim) == sorted(vrusim.__all__)
    for name in vrusim.__all__:
        value = getattr(vrusim, name)
        if name != "__version__":
            assert inspect.getdoc(value), name
    for cls in (vrusim.Results, vrusim.NcapResults, vrusim.NcapResults2026, vrusim.SweepFolder):
        for name, member in vars(cls).items():
            if not name.startswith("_") and (callable(member) or isinstance(member, property)):
                assert inspect.getdoc(member), f"{cls.__name__}.{name}"
    assert inspect.getdoc(Scenario.replace)
    with pytest.raises(AttributeError, match="no attribute 'nothing'"):
        _ = vrusim.nothing


# ----------------------------------------------------------------------------------------------- load


@pytest.mark.parametrize("name", sorted(BUNDLED))
def test_load_a_bundled_name(name):
    assert vrusim.load(name) == load_scenario(BUNDLED[name])


def test_load_a_yaml_path_as_text_or_path(pedestrian):
    assert vrusim.load(str(BUNDLED["paper:pedestrian"])) == pedestrian
    assert vrusim.load(BUNDLED["paper:pedestrian"]) == pedestrian
    assert vrusim.load(pedestrian) is pedestrian


def test_load_a_catalogue_test_id():
    (test,) = [t for t in select(protocol="2023", codes=["CPNCO-50"], night=False) if t.test_id == "CPNCO-50/30kph/day"]
    loaded = vrusim.load("CPNCO-50/30kph/day")
    assert loaded == build_test(test).scenario
    assert loaded.planner.name == "fsm"
    assert loaded.v2x.enabled is False
    assert loaded.v2x.rsu is not None  # so that run(..., v2x="on") can switch it on


@pytest.mark.parametrize(
    ("source", "message"),
    [
        ("paper:pedestrain", "source: no bundled scenario named 'paper:pedestrain'; did you mean paper:pedestrian"),
        ("CPNCO-50", "source: 'CPNCO-50' selects"),
        ("no-such-test", "source: 'no-such-test' is not a YAML file, a bundled name"),
        (42, "source: expected a Scenario"),
    ],
)
def test_load_refuses_what_names_no_scenario(source, message):
    with pytest.raises(UserInputError, match=re.escape(message)):
        vrusim.load(source)


def test_bundled_names_work_where_the_command_line_takes_a_source():
    result = invoke("run", "paper:pedestrian", "--v2x", "on", "--json")
    assert result.exit_code == 0, result.output
    row = json.loads(result.stdout)
    assert (row["scenario"], row["v2x"], row["collided"]) == ("paper-pedestrian-crossing", True, False)


# ----------------------------------------------------------------------------------------------- replace


def test_replace_sets_dotted_paths_and_leaves_the_original(pedestrian):
    changed = pedestrian.replace(
        **{"ego.cruise_speed_mps": 12.0, "vrus[0].top_speed_mps": 2, "v2x.channel": "typical", "name": "faster"}
    )
    assert (changed.ego.cruise_speed_mps, changed.vrus[0].top_speed_mps, changed.v2x.channel) == (12.0, 2.0, "typical")
    assert changed.name == "faster"
    assert pedestrian.ego.cruise_speed_mps == 15.0
    later = changed.replace(**{"v2x.channel.latency_s": 0.2})  # a profile name is expanded into its fields
    assert later.v2x.channel.latency_s == 0.2
    assert later.v2x.channel.loss == changed.v2x.channel_spec.loss
    assert pedestrian.replace() is pedestrian


def test_replace_gives_what_a_full_validation_gives(pedestrian):
    assert pedestrian.replace(**{"v2x.enabled": True}) == pedestrian.with_v2x(True)
    data = pedestrian.model_dump()
    data["ego"]["cruise_speed_mps"] = 11.0
    assert pedestrian.replace(**{"ego.cruise_speed_mps": 11.0}) == Scenario.model_validate(data)


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        ({"ego.cruise_speed_mps": -1.0}, "ego.cruise_speed_mps: Input should be greater than or equal to 0"),
        ({"vrus[0].top_speed_mps": "fast"}, "vrus[0].top_speed_mps: Input should be a valid number"),
        ({"ego.speed": 1.0}, "ego.speed: unknown field 'speed' in ego"),
        ({"vrus[3].top_speed_mps": 1.0}, "vrus[3].top_speed_mps: vrus has 1 element(s), no [3]"),
        ({"vrus[0].brake.decel_mps2": 3.0}, "vrus[0].brake is not set in the base scenario; give it a value first"),
        ({"v2x.channel": "realistic"}, "v2x.channel: unknown channel profile 'realistic'"),
        ({"v2x.channel.latency_s": 0.5}, "v2x.channel: track_max_age_s (0 s) must be at least latency_s"),
    ],
)
def test_replace_validates_and_names_the_path(pedestrian, changes, message):
    with pytest.raises(UserInputError) as caught:
        pedestrian.replace(**changes)
    assert str(caught.value).startswith("Scenario.replace: ")
    assert message in str(caught.value)


# ----------------------------------------------------------------------------------------------- run


def test_run_one_gives_the_engine_s_numbers_and_its_trace(pedestrian):
    results = vrusim.run(pedestrian)
    engine = simulate([pedestrian], trace=True)
    assert results.rows == summary_rows(engine) == summary_rows(simulate([pedestrian]))
    assert len(results) == 1
    assert list(results) == results.rows
    assert results[0]["collided"] is True
    assert results.trace.equals(trace_table(engine))
    assert results.trace.num_rows == engine.steps


def test_run_many_gives_the_engine_s_numbers(pedestrian):
    names = ["paper:pedestrian", "paper:escooter", "paper:motorcyclist"]
    results = vrusim.run(names, v2x="on")
    scenarios = [load_scenario(BUNDLED[name]).with_v2x(True) for name in names]
    assert results.rows == summary_rows(simulate(scenarios))
    assert list(results.scenarios) == scenarios
    with pytest.raises(ValueError, match="trace_of"):
        _ = results.trace
    with pytest.raises(ValueError, match=r"run\(\.\.\., trace=True\)"):
        results.trace_of(0)


def test_run_mixed_planners_keeps_the_order(pedestrian):
    aeb = pedestrian.replace(planner={"name": "aeb", "params": {}})
    results = vrusim.run([aeb, pedestrian, aeb.with_v2x(True)], trace=True)
    assert [row["planner"] for row in results] == ["aeb", "fsm", "aeb"]
    assert results.rows[1] == summary_rows(simulate([pedestrian]))[0]
    assert results.rows[2] == summary_rows(simulate([aeb.with_v2x(True)]))[0]
    assert results.trace_of(1).equals(trace_table(simulate([pedestrian], trace=True)))


def test_run_planner_v2x_and_seed(pedestrian):
    results = vrusim.run(pedestrian, planner="aeb", v2x="typical", seed=7, trace=False)
    (scenario,) = results.scenarios
    assert (scenario.planner.name, scenario.planner.params) == ("aeb", {})
    assert (scenario.v2x.enabled, scenario.v2x.channel, scenario.sim.seed) == (True, "typical", 7)
    assert results.rows == summary_rows(simulate([scenario]))
    with pytest.raises(ValueError, match="no trace"):
        _ = results.trace
    assert vrusim.run(pedestrian, v2x=True).scenarios[0] == pedestrian.with_v2x(True)
    assert vrusim.run(pedestrian.with_v2x(True), v2x="off").scenarios[0] == pedestrian


def test_run_settings_mean_what_vrusim_compare_does(pedestrian):
    from vrusim.scenario.settings import with_settings
    from vrusim.studies.compare import Combination, variant

    for planner, v2x, seed in [("aeb", "typical", 3), ("fsm", "off", 0), ("predictive", "ideal", 1)]:
        expected = variant(pedestrian, Combination(planner, v2x), seed)
        assert with_settings(pedestrian, planner, v2x, seed) == expected.model_copy(update={"name": pedestrian.name})


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        ({"planner": "warp-drive"}, "planner: "),
        ({"v2x": "maybe"}, "v2x: unknown V2X setting 'maybe'; expected one of: on, off, ideal"),
        ({"seed": -1}, "sim.seed: Input should be greater than or equal to 0"),
        ({"scenarios": []}, "scenarios: the list is empty"),
        ({"scenarios": ["paper:pedestrian", "paper:nope"]}, "scenarios[1]: no bundled scenario named 'paper:nope'"),
    ],
)
def test_run_refuses_bad_arguments_naming_them(pedestrian, arguments, message):
    arguments = {"scenarios": pedestrian} | arguments
    with pytest.raises(UserInputError) as caught:
        vrusim.run(**arguments)
    assert message in str(caught.value)


def test_run_v2x_on_needs_a_roadside_unit(pedestrian):
    data = pedestrian.model_dump()
    data["v2x"]["rsu"] = None
    with pytest.raises(UserInputError, match=r"v2x='on'.*\n  v2x: rsu .* is required when V2X is enabled"):
        vrusim.run(Scenario.model_validate(data), v2x="on")


# ----------------------------------------------------------------------------------------------- tables


def test_to_arrow_and_to_pandas_columns_and_types(pedestrian):
    results = vrusim.run([pedestrian.with_v2x(True), pedestrian.replace(**{"ego.cruise_speed_mps": 5.0})])
    assert not any(row["collided"] for row in results)  # so the impact columns hold no value at all
    table = results.to_arrow()
    assert table.column_names == list(results.rows[0])
    assert table.num_rows == 2
    types = dict(zip(table.column_names, table.schema.types, strict=True))
    assert types["scenario"] == pa.string()
    assert types["collided"] == pa.bool_()
    assert types["impact_side"] == pa.string()
    assert types["impact_vru"] == pa.int64()
    for name in ("contact_time_s", "impact_ego_speed_mps", "min_ttc_s", "safety"):
        assert types[name] == pa.float64(), name
    assert types["transitions"] == pa.list_(
        pa.struct([("t_s", pa.float64()), ("from", pa.string()), ("to", pa.string())])
    )
    assert all(field.type == pa.float64() for field in types["first_mode_s"])
    assert table.to_pylist() == results.rows

    frame = results.to_pandas()
    assert list(frame.columns) == list(results.rows[0])
    assert frame["contact_time_s"].dtype.kind == "f"
    assert frame["contact_time_s"].isna().all()
    assert frame["collided"].dtype == bool
    assert frame["safety"].tolist() == [row["safety"] for row in results]


def test_to_pandas_names_the_missing_package(pedestrian, monkeypatch):
    results = vrusim.run(pedestrian)
    monkeypatch.setitem(sys.modules, "pandas", None)
    with pytest.raises(ImportError, match=r"to_pandas\(\) needs the 'pandas' extra.*pip install 'vrusim\[pandas\]'"):
        results.to_pandas()


def test_results_show_briefly(pedestrian):
    one = vrusim.run(pedestrian)
    assert repr(one) == (
        "Results(paper-pedestrian-crossing: collision at 5.03 s; planner fsm, V2X off; "
        "safety 0.00, efficiency 0.00, comfort 0.00)"
    )
    many = vrusim.run([pedestrian, pedestrian.with_v2x(True)])
    assert repr(many) == "Results(2 runs: 1 collision, 1 avoided; planner fsm)"
    page = many._repr_html_()
    assert page.count("<tr>") == 3
    assert "<th>min_ttc_s</th>" in page
    assert "transitions" not in page


# ----------------------------------------------------------------------------------------------- Euro NCAP


def test_euro_ncap_subset_equals_the_command_line():
    ncap = vrusim.euro_ncap(["CPNA-25"], planner="aeb", v2x="on", protocol="2023")
    result = invoke("ncap", "--protocol", "2023", "--scenario", "CPNA-25", "--planner", "aeb", "--v2x", "on", "--json")
    assert result.exit_code == 0, result.output
    cli = json.loads(result.stdout)
    assert json.loads(json.dumps(ncap.to_dict(), allow_nan=False)) == cli
    assert (ncap.total, ncap.total_max) == (cli["assessment"]["total"], cli["assessment"]["total_max"])
    assert len(ncap) == len(cli["assessment"]["tests"]) == 11
    assert [row["test_id"] for row in ncap] == [test["test_id"] for test in cli["assessment"]["tests"]]
    table = ncap.to_arrow()
    assert table.column_names == list(ncap.rows[0])
    assert table.schema.field("impact_speed_kph").type == pa.float64()
    assert table.schema.field("colour").type == pa.string()
    assert repr(ncap).startswith("NcapResults(11 tests, planner aeb, V2X on: Euro NCAP total ")
    assert "<th>group</th>" in ncap._repr_html_()


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        ({"scenarios": "XYZ"}, "scenarios: unknown 2026 catalogue entry 'XYZ'"),
        ({"protocol": "1999"}, "protocol: unknown edition '1999'"),
        ({"planner": "warp-drive"}, "planner: "),
        ({"v2x": "typical"}, "v2x: expected on or off"),
        ({"night": "yes"}, "night: expected True or False"),
    ],
)
def test_euro_ncap_refuses_bad_arguments_naming_them(arguments, message):
    with pytest.raises(UserInputError, match=message):
        vrusim.euro_ncap(**arguments)


# ----------------------------------------------------------------------------------------------- sweeps

SMALL_SWEEP = {
    "name": "api-test",
    "base": "paper:pedestrian",
    "set": {"v2x.enabled": True},
    "parameters": {"ego.cruise_speed_mps": [10.0, 14.0], "v2x.channel": ["ideal", "lossy"]},
    "seed": 3,
    "batch_size": 3,
}


def test_run_sweep_and_read_it_back(tmp_path, pedestrian):
    out = tmp_path / "sweep"
    sweep = vrusim.run_sweep(SMALL_SWEEP, out=out)
    assert (sweep.outcome.variants, sweep.outcome.chunks, len(sweep), sweep.variants) == (4, 2, 4, 4)
    table = sweep.to_arrow()
    assert table.column("variant").to_pylist() == [0, 1, 2, 3]
    assert table.column("ego.cruise_speed_mps").to_pylist() == [10.0, 10.0, 14.0, 14.0]
    assert table.column("v2x.channel").to_pylist() == ["ideal", "lossy", "ideal", "lossy"]
    ideal = summary_rows(simulate([pedestrian.with_v2x(True).replace(**{"ego.cruise_speed_mps": 14.0, "sim.seed": 0})]))
    assert table.column("collided")[2].as_py() == ideal[0]["collided"]
    assert table.column("min_ttc_s")[2].as_py() == pytest.approx(ideal[0]["min_ttc_s"], abs=1e-6)
    assert list(sweep.to_pandas().columns) == table.column_names
    opened = vrusim.open_sweep(out)
    assert opened.to_arrow().equals(table)
    assert opened.outcome is None
    assert repr(opened) == f"SweepFolder({str(out)!r}: 4 of 4 variants finished)"
    summary = opened.summarize(by="v2x.channel")
    assert [group["key"] for group in summary["groups"]] == [{"v2x.channel": "ideal"}, {"v2x.channel": "lossy"}]
    with pytest.raises(UserInputError, match=r"out: .* already exists and is not empty; use resume=True"):
        vrusim.run_sweep(SMALL_SWEEP, out=out)
    assert vrusim.run_sweep(None, out=out, resume=True).outcome.chunks_run == 0


@pytest.mark.parametrize(
    ("spec", "message"),
    [
        (
            "example:no-such-spec",
            "spec: no bundled sweep spec named 'example:no-such-spec'; expected one of example:pedestrian-monte-carlo",
        ),
        (SMALL_SWEEP | {"base": "paper:nope"}, "spec: base: no bundled scenario named 'paper:nope'"),
        (SMALL_SWEEP | {"parameters": {"ego.speed": [1.0]}}, "parameters: ego.speed: unknown field 'speed' in ego"),
        (3, "spec: expected a sweep spec file"),
    ],
)
def test_run_sweep_refuses_bad_specs(tmp_path, spec, message):
    with pytest.raises(UserInputError, match=message):
        vrusim.run_sweep(spec, out=tmp_path / "never")
    assert not (tmp_path / "never").exists()


def test_open_sweep_refuses_a_folder_without_results(tmp_path):
    with pytest.raises(UserInputError, match="not a sweep results folder"):
        vrusim.open_sweep(tmp_path)


# ----------------------------------------------------------------------------------------------- notebook


def test_the_example_notebook_runs(tmp_path, monkeypatch):
    nbformat = pytest.importorskip("nbformat")
    nbclient = pytest.importorskip("nbclient")
    monkeypatch.setenv("JUPYTER_RUNTIME_DIR", str(tmp_path / "runtime"))
    monkeypatch.setenv("TMPDIR", str(tmp_path))  # the tour's sweep folder
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join([str(SRC), os.environ.get("PYTHONPATH", "")]))
    notebook = nbformat.read(REPO_ROOT / "examples" / "api_tour.ipynb", as_version=4)
    nbclient.NotebookClient(notebook, timeout=120, resources={"metadata": {"path": str(tmp_path)}}).execute()
    outputs = [output for cell in notebook.cells if cell.cell_type == "code" for output in cell.outputs]
    assert not [output for output in outputs if output.output_type == "error"]
    text = "\n".join(output.get("text", "") + output.get("data", {}).get("text/plain", "") for output in outputs)
    assert "ego.cruise_speed_mps: Input should be greater than or equal to 0" in text
    assert "NcapResults2026(30 tests, planner aeb, V2X off: FC Pedestrian & Cyclist 0.54)" in text
    assert "Spread(mean=" in text
    assert "SweepFolder(" in text and "6 of 6 variants finished" in text
    assert "['compiled (fsm)']" in text
