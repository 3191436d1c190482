"""tests/compile_steps.py, which the suite's controller runs before its workers start (tests/conftest.py)."""

from __future__ import annotations

import subprocess
import sys

from conftest import _COMPILED_STEPS, REPO_ROOT, wait_or_kill
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


def test_a_warm_up_that_hangs_is_killed_after_its_timeout():
    run = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(600)"])
    wait_or_kill(run, 0.5)
    assert run.returncode is not None and run.returncode < 0  # killed by a signal, not finished
