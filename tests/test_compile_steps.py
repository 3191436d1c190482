"""tests/compile_steps.py, which the suite's controller runs before its workers start (tests/conftest.py)."""

from __future__ import annotations

import subprocess
import sys

from conftest import _COMPILED_STEPS, REPO_ROOT
from vrusim.engine.compiled_run import COMPILED_PLANNERS


def test_the_warm_up_runs_the_compiled_step_of_every_built_in_planner():
    planners = [planner for group in _COMPILED_STEPS for planner in group]
    assert sorted(planners) == sorted(COMPILED_PLANNERS.values())  # every compiled step, once
    done = subprocess.run(
        [sys.executable, str(REPO_ROOT / "tests" / "compile_steps.py"), *planners],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert done.returncode == 0, done.stderr  # simulate(compiled=True) raises where a planner has no compiled step
