"""Shared fixtures: a minimal valid scenario mapping and the paper scenarios, to build tests from dicts."""

from __future__ import annotations

import contextlib
import copy
import os
import re
import signal
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, settings

from vrusim.scenario.loading import load_scenario, scenario_from_mapping
from vrusim.scenario.schema import Scenario

# Property tests draw their inputs from a fixed seed by default, so CI on a fresh clone (no example database)
# is reproducible; `HYPOTHESIS_PROFILE=explore python -m pytest` draws fresh random inputs to hunt for new cases.
# Both leave out timing checks (as Hypothesis's own CI profile does): the suite runs on parallel workers
# (pytest-xdist, pyproject.toml) on shared machines, where a slow example is a busy CPU, not a finding.
_UNTIMED = {"deadline": None, "suppress_health_check": [HealthCheck.too_slow]}
settings.register_profile("ci", derandomize=True, **_UNTIMED)
settings.register_profile("explore", derandomize=False, **_UNTIMED)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))

# The suite's own test planners are named `module:Class` (tests.warning_planner:WarnOnDetection, ...): the suite
# allows module planners as a user would (vrusim --allow-module-planners); tests of the refusal unset it.
os.environ["VRUSIM_ALLOW_MODULE_PLANNERS"] = "1"

# The command-line tests expect the width of a pipe (vrusim.cli.output: 120 columns unless COLUMNS is set);
# pytest-xdist's workers inherit COLUMNS=80 and LINES=24, which readline writes into the C environment of the
# main pytest process, and a developer's exported COLUMNS would change the width too. Tests that need a width
# pass COLUMNS themselves.
for _name in ("COLUMNS", "LINES"):
    os.environ.pop(_name, None)

# Numba's parallel kernels run on OpenMP threads, which by default spin at every barrier. Two test workers on two
# cores (or a CPU shared with other jobs) then make the threaded-kernel tests several times slower while the
# spinning thread waits for one that is not scheduled; sleeping threads lose nothing when the CPU is free.
# Set before numba loads its threading layer (on the first parallel call); results do not depend on it.
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

REPO_ROOT = Path(__file__).resolve().parents[1]
PAPER_DIR = REPO_ROOT / "scenarios" / "paper"
PAPER_FILES = sorted(PAPER_DIR.glob("*.yaml"))

FAR_VRU: dict[str, Any] = {
    "type": "pedestrian",
    "start": {"x_m": 500.0, "y_m": 50.0},
    "heading_deg": 90.0,
    "trigger": {"at_time_s": 1.0e6},
}
"""A VRU parked far off the ego's road that never starts moving (every scenario needs one VRU)."""


def minimal_scenario_dict() -> dict[str, Any]:
    """A fresh, valid, minimal scenario mapping: ego at the origin heading +x at 10 m/s, one far-away VRU."""
    return {
        "name": "test-minimal",
        "ego": {
            "start": {"x_m": 0.0, "y_m": 0.0, "heading_deg": 0.0},
            "cruise_speed_mps": 10.0,
            "route": {"kind": "straight", "length_m": 200.0},
            # explicit geometry (tests compute the rear axle and front bumper from these numbers)
            "length_m": 4.5,
            "width_m": 1.8,
            "wheelbase_m": 2.7,
            "rear_overhang_m": 0.9,
        },
        "planner": {"name": "none"},
        "vrus": [copy.deepcopy(FAR_VRU)],
        "sim": {"dt_s": 0.01, "duration_s": 5.0},
    }


def deep_update(base: dict[str, Any], changes: dict[str, Any]) -> dict[str, Any]:
    """Recursively merge `changes` into `base` (in place; lists and scalars are replaced) and return it."""
    for key, value in changes.items():
        if isinstance(value, dict) and isinstance(base.get(key), dict):
            deep_update(base[key], value)
        else:
            base[key] = copy.deepcopy(value)
    return base


@pytest.fixture
def scenario_dict() -> dict[str, Any]:
    """A fresh minimal valid scenario mapping that the test may modify freely."""
    return minimal_scenario_dict()


@pytest.fixture(scope="session")
def make_scenario() -> Callable[..., Scenario]:
    """Factory: `make_scenario(changes=None, base=None)` → validated Scenario (minimal mapping + changes).

    Session-scoped so that it can be used inside hypothesis tests.
    """

    def build(changes: dict[str, Any] | None = None, base: dict[str, Any] | None = None) -> Scenario:
        data = copy.deepcopy(base) if base is not None else minimal_scenario_dict()
        deep_update(data, changes or {})
        return scenario_from_mapping(data, "test")

    return build


@pytest.fixture(scope="session")
def paper_pedestrian_dict() -> dict[str, Any]:
    """The paper pedestrian-crossing scenario as a plain mapping (copy it before modifying)."""
    return load_scenario(PAPER_DIR / "pedestrian_crossing.yaml").model_dump(mode="json")


@pytest.fixture
def paper_pedestrian(paper_pedestrian_dict) -> dict[str, Any]:
    """A fresh copy of the paper pedestrian-crossing mapping that the test may modify."""
    return copy.deepcopy(paper_pedestrian_dict)


# ----------------------------------------------------------------------------------------------- parallel runs
# pyproject.toml runs the suite on pytest-xdist workers with `--dist loadgroup`, whose scheduler is replaced here:
# the tests of a file that defines a class-, module- or package-scoped fixture (a simulated batch, a calculator
# run, a browser) go to one worker together, so each such fixture is computed once rather than once per worker;
# every other test is handed out on its own. Work is handed out largest unit first (pytest-xdist's default), and
# a test's `xdist_group` mark still groups it where pytest-xdist honours it (it does not with pytest 9.2:
# pytest-xdist issue 1386). The scheduler sees only test ids, so it reads the files' text for the scopes.

_SHARED_SCOPE = re.compile(r"""scope\s*=\s*["'](?:class|module|package)["']""")


def _shares_fixtures(path: Path) -> bool:
    """Whether the test file at `path`, or a conftest.py it is under, defines a shared (non-function,
    non-session) fixture."""
    folders = [folder for folder in (path.parent, *path.parent.parents) if folder.is_relative_to(REPO_ROOT)]
    files = [path, *(folder / "conftest.py" for folder in folders)]
    return any(f.is_file() and _SHARED_SCOPE.search(f.read_text(encoding="utf-8")) for f in files)


try:
    from xdist.scheduler import LoadGroupScheduling
except ImportError:  # pytest-xdist is not installed: the suite runs in one process
    pass
else:

    class _FixtureFileScheduling(LoadGroupScheduling):
        """`--dist loadgroup`, with the tests of a file that shares fixtures grouped by file."""

        def __init__(self, config: pytest.Config, log=None) -> None:
            super().__init__(config, log)
            self._shared: dict[str, bool] = {}

        def _split_scope(self, nodeid: str) -> str:
            scope = super()._split_scope(nodeid)
            if scope != nodeid:  # an xdist_group mark
                return scope
            file = nodeid.split("::", 1)[0]
            if file not in self._shared:
                path = self.config.rootpath / file
                self._shared[file] = path.suffix == ".py" and _shares_fixtures(path)
            return file if self._shared[file] else nodeid

    @pytest.hookimpl(tryfirst=True)
    def pytest_xdist_make_scheduler(config: pytest.Config, log):
        if config.getvalue("dist") == "loadgroup":
            return _FixtureFileScheduling(config, log)
        return None


# ------------------------------------------------------------------------------------- kernels compiled once
# On a cold kernel cache (the first run after a source change, so every CI run) each worker would compile the
# built-in planners' compiled steps itself, about 20-30 s each, and their traced versions as well. The
# controller compiles them first with `vrusim compile --part compiled,per-step` (two processes at once), before it
# starts the workers, which then load them from the cache. On a warm cache it only loads them (about 5 s). Only
# for the whole suite (no test paths given): a single file after a source change compiles what it uses.
WARM_UP = [sys.executable, "-m", "vrusim", "compile", "--part", "compiled,per-step", "--jobs", "2"]
_WARM_UP_TIMEOUT_S = 600.0
"""Longest the controller waits for the warm-up (about 2 minutes on a cold cache here), s."""


@pytest.hookimpl(tryfirst=True)
def pytest_sessionstart(session: pytest.Session) -> None:
    config = session.config
    if hasattr(config, "workerinput") or not config.pluginmanager.has_plugin("dsession"):
        return  # a worker, or a run without workers
    if config.args_source != pytest.Config.ArgsSource.TESTPATHS:
        return  # test paths or ids given
    run = subprocess.Popen(WARM_UP, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    wait_or_kill(run, _WARM_UP_TIMEOUT_S)  # a failure shows in the tests that use the kernels


def wait_or_kill(run: subprocess.Popen, timeout_s: float) -> None:
    """Wait for `run` (started in a session of its own) at most `timeout_s`, then kill it and every process of
    its session (`vrusim compile`'s worker processes; the suite's workers then compile what they need)."""
    try:
        run.wait(timeout=timeout_s)
    except subprocess.TimeoutExpired:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(run.pid, signal.SIGKILL)
        run.wait()
