"""Process start: the command line imports only what a command needs, and a cold start (kernels compiling) says
so on stderr while a warm one says nothing."""

from __future__ import annotations

import gc
import io
import json
import os
import subprocess
import sys
from pathlib import Path

import numba
import pytest

import vrusim
from vrusim.cli.app import GC_THRESHOLDS, main
from vrusim.kernel_notices import compile_notices

SRC = Path(vrusim.__file__).resolve().parents[1]

HEAVY = ("matplotlib", "pandas", "pyarrow", "scipy", "plotly", "openpyxl", "PIL", "numba", "pydantic", "yaml")
"""Libraries that `import vrusim.cli.app`, `vrusim --version` and `vrusim --help` must not load."""

_PROBE = f"""
import json, sys
import vrusim.cli.app
after_import = sorted(m for m in {HEAVY!r} if m in sys.modules)
for argv in (["--version"], ["--help"]):
    try:
        vrusim.cli.app.main(argv)
    except SystemExit:
        pass
after_commands = sorted(m for m in {HEAVY!r} if m in sys.modules)
print(json.dumps({{"import": after_import, "commands": after_commands}}))
"""


def _python(code: str, **env: str) -> subprocess.CompletedProcess:
    environment = os.environ | {"PYTHONPATH": str(SRC)} | env
    return subprocess.run([sys.executable, "-c", code], env=environment, capture_output=True, text=True, check=True)


def test_the_command_line_imports_no_heavy_library_until_a_command_needs_it():
    report = json.loads(_python(_PROBE).stdout.splitlines()[-1])
    assert report == {"import": [], "commands": []}


def _tiny_kernel(x: float) -> float:
    return x + 1.0


def test_a_compiling_kernel_is_announced_and_a_cached_one_is_not(tmp_path, monkeypatch):
    monkeypatch.setattr(numba.config, "CACHE_DIR", str(tmp_path))  # an empty cache: this kernel must compile
    cold = io.StringIO()
    with compile_notices(cold):
        assert numba.njit(cache=True)(_tiny_kernel)(1.0) == 2.0
    lines = cold.getvalue().splitlines()
    assert len(lines) == 2 and lines[0].startswith("vrusim: compiling the simulation kernels"), lines
    assert str(tmp_path) in lines[0]
    assert lines[1].startswith("vrusim: compiled kernel 1 (") and "_tiny_kernel" in lines[1], lines

    warm = io.StringIO()
    with compile_notices(warm):
        assert numba.njit(cache=True)(_tiny_kernel)(1.0) == 2.0  # a new dispatcher: loaded from the cache
    assert warm.getvalue() == ""

    after = io.StringIO()
    monkeypatch.setattr(sys, "stderr", after)
    monkeypatch.setattr(numba.config, "CACHE_DIR", str(tmp_path / "other"))
    numba.njit(cache=True)(_tiny_kernel)(1.0)  # compiles, but outside a block: no notice
    assert after.getvalue() == ""


def test_notices_asked_for_before_numba_loads_attach_when_the_kernels_module_loads(tmp_path):
    code = """
import sys
from vrusim.kernel_notices import compile_notices
with compile_notices():
    assert "numba" not in sys.modules
    from vrusim.kernels import njit
    from tests_startup_kernel import twice
    print(njit(cache=True)(twice)(2.0))
"""
    (tmp_path / "tests_startup_kernel.py").write_text("def twice(x):\n    return 2.0 * x\n", encoding="utf-8")
    done = _python(code, NUMBA_CACHE_DIR=str(tmp_path / "cache"), PYTHONPATH=f"{SRC}{os.pathsep}{tmp_path}")
    assert done.stdout.strip() == "4.0"  # stdout is the program's alone
    assert "vrusim: compiling the simulation kernels" in done.stderr
    assert "compiled kernel 1 (tests_startup_kernel.twice)" in done.stderr


def test_a_cold_run_says_so_on_stderr_and_keeps_json_on_stdout_clean(tmp_path, monkeypatch, capsys):
    import vrusim.engine.simulate as engine

    simulate = engine.simulate

    def cold_simulate(*args, **kwargs):
        # a kernel that is not in the (empty) cache compiles when the command simulates, as on a cold start
        monkeypatch.setattr(numba.config, "CACHE_DIR", str(tmp_path))
        numba.njit(cache=True)(_tiny_kernel)(1.0)
        return simulate(*args, **kwargs)

    monkeypatch.setattr(engine, "simulate", cold_simulate)
    with pytest.raises(SystemExit) as exit_code:
        main(["run", "paper:pedestrian", "--json"])
    assert exit_code.value.code in (0, None)
    out, err = capsys.readouterr()
    assert json.loads(out)["scenario"] == "paper-pedestrian-crossing"
    assert "vrusim: compiling the simulation kernels" in err and "compiled kernel 1" in err


def test_limits_held_reads_each_limit_once_and_a_grid_build_still_applies_them(monkeypatch):
    from pydantic import ValidationError

    from vrusim.limits import limit, limits_held
    from vrusim.ncap.grid import run_tests, select

    monkeypatch.setenv("VRUSIM_LIMIT_SPEED_MPS", "5")
    with limits_held():
        assert limit("speed_mps") == 5.0
        monkeypatch.setenv("VRUSIM_LIMIT_SPEED_MPS", "7")
        assert limit("speed_mps") == 5.0  # read once in the block
    assert limit("speed_mps") == 7.0
    monkeypatch.setenv("VRUSIM_LIMIT_SPEED_MPS", "1")
    with pytest.raises(ValidationError, match="VRUSIM_LIMIT_SPEED_MPS"):
        run_tests(select(["CPNA"], protocol="2026"))  # built inside limits_held: the limit applies


_CACHED_KERNEL = """
import sys
import numpy as np
from numba.core.base import BaseContext
from vrusim.geometry.ttc import ttc_batch

refreshed = []
real_refresh = BaseContext.refresh
BaseContext.refresh = lambda context: refreshed.append(context) or real_refresh(context)
out = np.zeros((1, 1))
ones = np.ones(1)
ttc_batch(1, np.zeros(1), np.zeros(1), ones, np.zeros(1), ones, ones, ones, np.full((1, 1), 10.0), np.zeros((1, 1)),
          np.ones((1, 1)), np.zeros((1, 1)), np.zeros((1, 1)), out)
print(out[0, 0], len(refreshed))
"""


def test_a_kernel_loaded_from_the_cache_does_not_refresh_numbas_contexts(tmp_path):
    first = _python(_CACHED_KERNEL, NUMBA_CACHE_DIR=str(tmp_path)).stdout.split()  # compiles: numba refreshes
    second = _python(_CACHED_KERNEL, NUMBA_CACHE_DIR=str(tmp_path)).stdout.split()  # loads it from the cache
    assert first[0] == second[0] == "8.0"  # 10 m ahead, closing at 1 m/s, half length 1 m and radius 1 m
    assert int(first[1]) > 0
    assert second[1] == "0"


_EXIT_PROBE = """
import atexit, gc, sys
atexit.register(lambda: print("at exit:", gc.get_threshold()[0], gc.get_freeze_count() > 0))
sys.argv = ["vrusim", "--version"]
from vrusim.cli.app import main
main({argv})
"""


def test_the_command_line_tunes_the_collector_only_when_the_process_is_its_own():
    # collections over numba's and pydantic's objects took about 0.1 s of `vrusim ncap` while they were created
    # and about 0.2 s of each command's shutdown
    version = f"vrusim {vrusim.__version__}"
    own = _python(_EXIT_PROBE.format(argv="")).stdout.splitlines()
    assert own == [version, f"at exit: {GC_THRESHOLDS[0]} True"]
    kept = _python(_EXIT_PROBE.format(argv='["--version"]')).stdout.splitlines()  # a caller that goes on
    assert kept == [version, f"at exit: {gc.get_threshold()[0]} False"]
    assert gc.get_threshold()[0] < GC_THRESHOLDS[0]


def test_a_batch_kernel_makes_its_dispatchers_when_first_called():
    code = """
import numpy as np
from vrusim.geometry.contact import clearance_batch
print(clearance_batch._serial is None, clearance_batch._parallel is None)
clearance = np.zeros((3, 1, 1))
ones = np.ones(1)
clearance_batch(1, np.zeros(1), np.zeros(1), ones, np.zeros(1), ones, ones, np.full((1, 1), 3.0), np.zeros((1, 1)),
                np.ones((1, 1)), clearance)
print(clearance_batch._serial is None, clearance_batch._parallel is None, clearance[0, 0, 0])
"""
    assert _python(code).stdout.split() == ["True", "True", "False", "True", "1.0"]  # only the serial one, used


def test_the_low_speed_planners_are_imported_when_a_run_names_them():
    code = """
import sys
from vrusim.engine.simulate import simulate
from vrusim.planners.registry import make_planner
low_speed = ("vrusim.planners.acpe", "vrusim.planners.dow", "vrusim.planners.reverse_aeb")
print(sorted(m for m in low_speed if m in sys.modules))
print(type(make_planner("dow")).__name__, sorted(m for m in low_speed if m in sys.modules))
"""
    lines = _python(code).stdout.splitlines()
    assert lines == ["[]", "DowPlanner ['vrusim.planners.dow']"]
