"""`vrusim compile` / `vrusim.compile_kernels`: kernels compiled ahead of time are the ones later commands load,
bad arguments are user errors, and the test suite's own warm-up (tests/conftest.py) uses the command."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

from cli_helpers import assert_user_error, invoke
from conftest import WARM_UP, wait_or_kill
from vrusim.api.compiling import COMPILED_STEP_PLANNERS, PARTS, CompileTask, compile_kernels, compile_tasks
from vrusim.engine.compiled_run import COMPILED_PLANNERS
from vrusim.errors import UserInputError


def test_tasks_cover_each_part_of_each_planner_longest_first():
    assert compile_tasks(["fsm", "acpe"], PARTS) == [
        CompileTask(("compiled", "ncap"), "fsm"),  # the grids after the compiled step they use
        CompileTask(("ncap",), "acpe"),  # acpe has no compiled step
        CompileTask(("per-step", "threaded"), "fsm"),
        CompileTask(("per-step", "threaded"), "acpe"),
    ]
    assert compile_tasks(["aeb"], ["threaded", "compiled"]) == [
        CompileTask(("compiled",), "aeb"),
        CompileTask(("threaded",), "aeb"),
    ]
    assert CompileTask(("compiled", "ncap"), "fsm").name == "compiled + ncap (fsm)"
    assert set(COMPILED_STEP_PLANNERS) == set(COMPILED_PLANNERS.values())


@pytest.mark.parametrize(
    ("args", "names"),
    [
        (["--planner", "fsm,nope"], ["--planner", "'nope'", "fsm, none"]),
        (["--planner", "mypkg.mod:Planner"], ["--planner", "plug-in"]),
        (["--part", "compiled,everything"], ["--part", "'everything'", "compiled, ncap, per-step, threaded"]),
        (["--jobs", "0"], ["--jobs", ">= 1", "0"]),
        (["--planner", "dow", "--part", "compiled"], ["--part", "nothing to compile", "dow"]),
    ],
)
def test_bad_arguments_are_user_errors(args, names):
    assert_user_error(invoke("compile", *args), *names)


@pytest.mark.parametrize(("jobs", "text"), [(-1, ">= 1"), (1.5, "whole number"), (True, "whole number")])
def test_the_api_refuses_a_bad_job_count(jobs, text):
    with pytest.raises(UserInputError, match=text):
        compile_kernels(jobs=jobs)


def test_the_api_takes_one_name_as_a_string():
    with pytest.raises(UserInputError, match="got 'nope'"):
        compile_kernels("nope")
    with pytest.raises(UserInputError, match="nothing to compile for compiled with dow"):
        compile_kernels("dow", "compiled")


def test_compile_without_a_writable_cache_folder_is_a_user_error(tmp_path):
    not_a_folder = tmp_path / "file"
    not_a_folder.write_text("x")
    env = {**os.environ, "NUMBA_CACHE_DIR": str(not_a_folder / "kernels")}
    done = subprocess.run(
        [sys.executable, "-m", "vrusim", "compile"], env=env, capture_output=True, text=True, timeout=120
    )
    assert done.returncode == 2, done.stderr
    assert "NUMBA_CACHE_DIR" in done.stderr and "writable folder" in done.stderr
    assert "Traceback" not in done.stderr and done.stdout == ""


def test_a_command_after_compile_compiles_nothing(tmp_path):
    """On an empty kernel cache: `vrusim compile` of the per-step part for the `none` planner, then a run with a
    trace (one variant: recorded by the planner's compiled step) with that planner says nothing about compiling;
    with another planner, whose compiled step was not compiled, it does."""
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "kernels")}

    def vrusim(*args: str) -> subprocess.CompletedProcess:
        command = [sys.executable, "-m", "vrusim", *args]
        done = subprocess.run(command, env=env, capture_output=True, text=True, timeout=600)
        assert done.returncode == 0, done.stderr
        return done

    compiled = vrusim("compile", "--planner", "none", "--part", "per-step", "--jobs", "1", "--json")
    report = json.loads(compiled.stdout)
    assert report["folder"] == env["NUMBA_CACHE_DIR"]
    assert list(report["tasks_s"]) == ["per-step (none)"]
    assert "vrusim: [1/1] per-step (none) ready in" in compiled.stderr

    def traced(planner: str) -> subprocess.CompletedProcess:
        return vrusim("run", "paper:pedestrian", "--planner", planner, "--trace", str(tmp_path / f"{planner}.csv"))

    assert "compil" not in traced("none").stderr
    other = traced("fsm").stderr
    assert "compiling the simulation kernels" in other and "compiled_run._run_fsm" in other  # the check can fail


def test_the_suite_warm_up_compiles_every_compiled_step():
    """The controller's warm-up (tests/conftest.py) is `vrusim compile --part compiled,per-step`: every built-in
    planner's compiled step, untraced and traced, and the per-step path, loaded from the cache here."""
    done = subprocess.run([*WARM_UP, "--json"], capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    ran = json.loads(done.stdout)["tasks_s"]
    planners = COMPILED_PLANNERS.values()
    assert sorted(ran) == sorted(f"{part} ({planner})" for planner in planners for part in ("compiled", "per-step"))


_SPAWNS_A_SLEEPER = """
import subprocess, sys, time
child = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(600)"])
print(child.pid, flush=True)
time.sleep(600)
"""


def _running(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except (FileNotFoundError, ProcessLookupError):
        return False
    return state != "Z"  # a zombie has ended (nobody reaped it yet)


def test_a_warm_up_that_hangs_is_killed_after_its_timeout_with_its_children():
    run = subprocess.Popen(
        [sys.executable, "-c", _SPAWNS_A_SLEEPER], stdout=subprocess.PIPE, text=True, start_new_session=True
    )
    child = int(run.stdout.readline())
    assert _running(child)
    wait_or_kill(run, 0.5)
    run.stdout.close()
    assert run.returncode is not None and run.returncode < 0  # killed by a signal, not finished
    deadline = time.monotonic() + 10.0
    while _running(child) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert not _running(child)
