"""The worked example of docs/planners.md (examples/planner_plugin): by `module:Class` and by entry point,
plus the registry's entry-point look-up and its errors (a fake distribution, nothing installed)."""

from __future__ import annotations

import importlib.metadata
import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from cli_helpers import assert_user_error, invoke
from vrusim.engine.simulate import simulate
from vrusim.errors import UserInputError
from vrusim.metrics.summary import summary_rows
from vrusim.paper.cases import scenario_dir
from vrusim.planners.fsm import FsmPlanner
from vrusim.planners.registry import (
    ENTRY_POINT_GROUP,
    MODULE_PLANNERS_ENV,
    MODULE_PLANNERS_FLAG,
    allow_module_planners,
    make_planner,
)
from vrusim.scenario.loading import load_scenario

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "planner_plugin"
DOCS = ROOT / "docs" / "planners.md"
MODULE_PATH = "mypkg.brake_on_detection:BrakeOnDetection"


def fake_entry_points(monkeypatch, **registered: str) -> None:
    """Pretend installed distributions register `name = "module:Class"` under vrusim.planners (and others)."""
    entries = [importlib.metadata.EntryPoint(name, value, ENTRY_POINT_GROUP) for name, value in registered.items()]
    entries.append(importlib.metadata.EntryPoint("other", "os:getcwd", "some.other.group"))

    def entry_points(**selection):
        chosen = (e for e in entries if all(getattr(e, k) == v for k, v in selection.items()))
        return importlib.metadata.EntryPoints(chosen)

    monkeypatch.setattr(importlib.metadata, "entry_points", entry_points)


@pytest.fixture
def example_on_path(monkeypatch):
    monkeypatch.syspath_prepend(str(EXAMPLE))


def pedestrian(name: str, v2x: bool):
    scenario = load_scenario(scenario_dir() / "pedestrian_crossing.yaml").with_v2x(v2x)
    planner = scenario.planner.model_copy(update={"name": name, "params": {"decel_mps2": 4.0}})
    return scenario.model_copy(update={"planner": planner})


def test_docs_show_the_example_file_verbatim():
    text = DOCS.read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, flags=re.S)
    example = (EXAMPLE / "mypkg" / "brake_on_detection.py").read_text()
    assert example in blocks
    entry_point = re.search(r'^brake-on-detection = "(.+)"$', (EXAMPLE / "pyproject.toml").read_text(), re.M)
    assert entry_point is not None and entry_point.group(1) == MODULE_PATH
    assert f'brake-on-detection = "{MODULE_PATH}"' in text


def test_example_by_module_path_behaves_as_documented(example_on_path):
    with_v2x, without = summary_rows(simulate([pedestrian(MODULE_PATH, True), pedestrian(MODULE_PATH, False)]))
    assert with_v2x["first_mode_s"]["braking"] == pytest.approx(2.10)
    assert not with_v2x["collided"]
    assert with_v2x["min_clearance_m"] == pytest.approx(3.88, abs=0.005)
    assert with_v2x["min_ttc_s"] == pytest.approx(1.39, abs=0.005)
    # it never drives on: stalled, no trip time, efficiency 0 (issue 17; before: trip 28.24 s, 0.93 / 0.22 / 0.81)
    assert with_v2x["outcome"] == "stalled" and with_v2x["trip_time_s"] is None
    scores = (with_v2x["safety"], with_v2x["efficiency"], with_v2x["comfort"])
    assert scores == pytest.approx((0.93, 0.0, 0.46), abs=0.005)
    assert without["first_mode_s"]["braking"] == pytest.approx(3.06)
    assert without["collided"]
    assert without["contact_time_s"] == pytest.approx(5.01, abs=0.005)
    assert without["impact_ego_speed_mps"] == pytest.approx(7.69, abs=0.005)


def test_example_by_entry_point_runs_the_same(monkeypatch, example_on_path):
    fake_entry_points(monkeypatch, **{"brake-on-detection": MODULE_PATH})
    by_name = summary_rows(simulate([pedestrian("brake-on-detection", True)]))[0]
    by_path = summary_rows(simulate([pedestrian(MODULE_PATH, True)]))[0]
    for key in ("first_mode_s", "collided", "min_clearance_m", "min_ttc_s", "safety", "efficiency", "comfort"):
        assert by_name[key] == by_path[key], key
    assert by_name["planner"] == "brake-on-detection"


def test_unknown_name_lists_registered_planners(monkeypatch):
    fake_entry_points(monkeypatch, mine="tests.warning_planner:WarnOnDetection")
    with pytest.raises(UserInputError, match=r"planner\.name: unknown planner 'warp'; expected one of .*mine") as error:
        make_planner("warp")
    for builtin in ("fsm", "none", "aeb", "predictive"):
        assert builtin in str(error.value)
    assert "vrusim.planners" in str(error.value)
    assert type(make_planner("mine")).__name__ == "WarnOnDetection"


@pytest.mark.parametrize(
    ("value", "message"),
    [
        ("no_such_module_xyz:Planner", r"cannot load 'broken' \(entry point 'no_such_module_xyz:Planner'\)"),
        ("os:getcwd", r"'broken' \(entry point 'os:getcwd'\) is not a class"),
        ("vrusim.errors:UserInputError", r"has no reset\(params\) and act\(observation\) methods"),
    ],
)
def test_broken_entry_points_are_user_errors_naming_planner_name(monkeypatch, value, message):
    fake_entry_points(monkeypatch, broken=value)
    with pytest.raises(UserInputError, match=rf"^planner\.name: .*{message}"):
        make_planner("broken")


def test_conflicting_registrations_are_a_user_error(monkeypatch):
    entries = [
        importlib.metadata.EntryPoint("twin", "a.b:C", ENTRY_POINT_GROUP),
        importlib.metadata.EntryPoint("twin", "d.e:F", ENTRY_POINT_GROUP),
    ]
    monkeypatch.setattr(importlib.metadata, "entry_points", lambda **_: importlib.metadata.EntryPoints(entries))
    with pytest.raises(UserInputError, match=r"planner\.name: entry point 'twin' .* registered twice"):
        make_planner("twin")


def test_builtins_cannot_be_shadowed_by_an_entry_point(monkeypatch):
    fake_entry_points(monkeypatch, fsm="tests.warning_planner:WarnOnDetection")
    assert isinstance(make_planner("fsm"), FsmPlanner)


def test_entry_points_are_not_consulted_for_builtins_or_module_paths(monkeypatch):
    def fail(**_):
        raise AssertionError("entry points read")

    monkeypatch.setattr(importlib.metadata, "entry_points", fail)
    for name in ("fsm", "none", "aeb", "predictive", "tests.warning_planner:WarnOnDetection"):
        make_planner(name)


def test_plugin_source_names_the_module_file_and_its_hash(monkeypatch, example_on_path):
    """What a sweep manifest records of a plug-in planner, by module path and by entry point."""
    import hashlib

    from vrusim.planners.registry import plugin_source

    module_file = EXAMPLE / "mypkg" / "brake_on_detection.py"
    expected = {
        "module": "mypkg.brake_on_detection",
        "file": str(module_file),
        "sha256": hashlib.sha256(module_file.read_bytes()).hexdigest(),
    }
    assert plugin_source("fsm") is None  # built-ins are covered by vrusim's own source digest
    assert plugin_source(MODULE_PATH) == {"planner": MODULE_PATH, **expected}
    fake_entry_points(monkeypatch, **{"brake-on-detection": MODULE_PATH})
    assert plugin_source("brake-on-detection") == {"planner": "brake-on-detection", "distribution": None, **expected}
    with pytest.raises(UserInputError, match=r"planner\.name: unknown planner 'nope'"):
        plugin_source("nope")


# ------------------------------------------------------------------------------------------------------------
# A scenario file names a module: nothing is imported unless the user allows it outside the file
# ------------------------------------------------------------------------------------------------------------
MARKER_MODULE = """
from pathlib import Path

Path(__file__).with_name("imported.marker").write_text("module code ran")

from vrusim.planners.base import HoldSpeedPlanner


class Hold(HoldSpeedPlanner):
    pass
"""


@pytest.fixture
def marker_scenario(tmp_path):
    """A module that writes `imported.marker` next to itself when imported, and a scenario naming it."""
    (tmp_path / "marker_planner.py").write_text(MARKER_MODULE)
    data = load_scenario(scenario_dir() / "pedestrian_crossing.yaml").model_dump(mode="json")
    data["planner"] = {"name": "marker_planner:Hold", "params": {}}
    data["sim"]["duration_s"] = 2.0
    path = tmp_path / "scenario.yaml"
    path.write_text(yaml.safe_dump(data))
    return path, tmp_path / "imported.marker"


def _python_m(*args, cwd: Path, pythonpath: str | None = None, allow_env: bool = False):
    env = {k: v for k, v in os.environ.items() if k not in (MODULE_PLANNERS_ENV, "PYTHONPATH")}
    if pythonpath is not None:
        env["PYTHONPATH"] = pythonpath
    if allow_env:
        env[MODULE_PLANNERS_ENV] = "1"
    return subprocess.run(
        [sys.executable, "-m", "vrusim", *map(str, args)], cwd=cwd, env=env, capture_output=True, text=True
    )


@pytest.mark.parametrize(
    "args",
    [("run", "{s}"), ("run", "{s}", "--planner", "marker_planner:Hold"), ("ncap", "--scenario", "CPNA",
     "--planner", "marker_planner:Hold")],
)  # fmt: skip
def test_a_module_planner_is_refused_before_import_without_the_opt_in(marker_scenario, monkeypatch, args):
    scenario, marker = marker_scenario
    monkeypatch.delenv(MODULE_PLANNERS_ENV)
    monkeypatch.syspath_prepend(str(scenario.parent))  # importable, so only the missing opt-in stops it
    result = invoke(*[a.replace("{s}", str(scenario)) for a in args])
    assert_user_error(result, "planner", "marker_planner:Hold", MODULE_PLANNERS_FLAG, MODULE_PLANNERS_ENV)
    assert not marker.exists() and "marker_planner" not in sys.modules


def test_a_sweep_dry_run_imports_nothing_without_the_opt_in(marker_scenario, monkeypatch, tmp_path):
    scenario, marker = marker_scenario
    monkeypatch.delenv(MODULE_PLANNERS_ENV)
    monkeypatch.syspath_prepend(str(scenario.parent))
    spec = tmp_path / "sweep.yaml"
    spec.write_text(yaml.safe_dump({"base": str(scenario), "parameters": {"ego.cruise_speed_mps": [10.0, 12.0]}}))
    result = invoke("sweep", spec, "--dry-run", "--out", tmp_path / "out")
    assert_user_error(result, "marker_planner:Hold", MODULE_PLANNERS_FLAG)
    assert not marker.exists() and not (tmp_path / "out").exists()


def test_python_m_never_imports_from_the_current_folder(marker_scenario):
    """`python -m vrusim` run next to the module: refused without the opt-in, and with it the module is still not
    found (the current folder is not searched); only an explicit PYTHONPATH plus the opt-in runs it."""
    scenario, marker = marker_scenario
    folder = scenario.parent
    refused = _python_m("run", scenario.name, cwd=folder)
    assert refused.returncode == 2 and MODULE_PLANNERS_FLAG in refused.stderr and "Traceback" not in refused.stderr
    assert not marker.exists()
    not_found = _python_m(MODULE_PLANNERS_FLAG, "run", scenario.name, cwd=folder)
    assert not_found.returncode == 2 and "cannot import 'marker_planner:Hold'" in not_found.stderr
    assert not marker.exists()
    ran = _python_m("run", scenario.name, "--json", cwd=folder, pythonpath=str(folder), allow_env=True)
    assert ran.returncode == 0, ran.stderr
    assert marker.exists() and json.loads(ran.stdout)["planner"] == "marker_planner:Hold"


def test_the_python_switch_allows_and_forbids_module_planners(monkeypatch):
    monkeypatch.delenv(MODULE_PLANNERS_ENV)
    with pytest.raises(UserInputError, match=MODULE_PLANNERS_FLAG):
        make_planner("tests.warning_planner:WarnOnDetection")
    allow_module_planners()
    assert make_planner("tests.warning_planner:WarnOnDetection") is not None
    allow_module_planners(False)
    with pytest.raises(UserInputError, match=MODULE_PLANNERS_ENV):
        make_planner("tests.warning_planner:WarnOnDetection")
