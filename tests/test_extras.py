"""The slim core install: optional libraries belong to extras, a feature whose extra is missing says which one to
install (exit code 2), the core imports none of them, and the installed environment's requirements hold."""

from __future__ import annotations

import re
import subprocess
import sys
import tomllib

import pytest

from cli_helpers import assert_user_error, invoke
from conftest import PAPER_DIR, REPO_ROOT
from vrusim.errors import UserInputError
from vrusim.extras import EXTRAS, MissingExtraError, extra

PEDESTRIAN = PAPER_DIR / "pedestrian_crossing.yaml"
ADAPTERS = ("vrusim.interop", "vrusim.gym")
"""The packages that import optional libraries at their top (imported only by the features needing them)."""
NOT_CORE = sorted({module for e in EXTRAS.values() for module in e.packages} | {"scipy", "imageio", "psutil", "pandas"})
"""Top-level modules the core must run without: every extra's, and the test-only ones."""


def uninstall(monkeypatch: pytest.MonkeyPatch, *modules: str) -> None:
    """Make `modules` (top-level names) look uninstalled for this test: importing them raises
    ModuleNotFoundError, and the adapter packages are imported afresh (as in a new process)."""
    for name in list(sys.modules):
        if name.partition(".")[0] in modules or name.startswith(ADAPTERS):
            parent, _, child = name.rpartition(".")
            if parent in sys.modules and hasattr(sys.modules[parent], child):  # restored with the module
                monkeypatch.setattr(sys.modules[parent], child, getattr(sys.modules[parent], child))
            monkeypatch.delitem(sys.modules, name)
    for module in modules:
        monkeypatch.setitem(sys.modules, module, None)


def assert_names_extra(result, name: str, package: str) -> None:
    assert_user_error(result, f"'{name}' extra", f"{package} is not installed", f"pip install 'vrusim[{name}]'")


# ------------------------------------------------------------------------------------- a command, its extra


@pytest.mark.parametrize(
    ("fmt", "module", "package"),
    [("openscenario", "scenariogeneration", "scenariogeneration"), ("commonroad", "commonroad", "commonroad-io")],
)
def test_export_without_the_export_extra_says_so(monkeypatch, tmp_path, fmt, module, package):
    uninstall(monkeypatch, module)
    result = invoke("export", PEDESTRIAN, "--format", fmt, "--out", tmp_path / "out")
    assert_names_extra(result, "export", package)
    assert "vrusim export needs" in result.output
    assert not (tmp_path / "out").exists()


def test_an_mp4_without_the_video_extra_says_so_before_simulating(monkeypatch, tmp_path):
    uninstall(monkeypatch, "imageio_ffmpeg")
    result = invoke("run", PEDESTRIAN, "--animate", tmp_path / "run.mp4")
    assert_names_extra(result, "video", "imageio-ffmpeg")
    assert "--animate" in result.output
    assert list(tmp_path.iterdir()) == []


def test_a_gif_needs_no_extra(monkeypatch, tmp_path):
    from vrusim.viz.animate import check_animation_path

    uninstall(monkeypatch, "imageio_ffmpeg")
    assert check_animation_path(tmp_path / "run.gif") == tmp_path / "run.gif"


def test_a_dask_scheduler_without_the_dask_extra_says_so_before_writing(monkeypatch, tmp_path):
    uninstall(monkeypatch, "distributed")
    spec = REPO_ROOT / "sweeps" / "pedestrian_monte_carlo.yaml"
    result = invoke("sweep", spec, "--out", tmp_path / "sweep", "--scheduler", "tcp://127.0.0.1:1")
    assert_names_extra(result, "dask", "distributed")
    assert not (tmp_path / "sweep").exists()


def test_the_gym_package_without_the_gym_extra_says_so(monkeypatch):
    uninstall(monkeypatch, "gymnasium")
    with pytest.raises(MissingExtraError, match=re.escape("needs the 'gym' extra")) as raised:
        import vrusim.gym  # noqa: F401
    assert isinstance(raised.value, UserInputError) and isinstance(raised.value, ImportError)
    assert "pip install 'vrusim[gym]'" in str(raised.value)


def test_the_gym_package_imports_with_the_extra():
    import vrusim.gym

    assert vrusim.gym.ENV_IDS


# ------------------------------------------------------------------------------------------- the helper


def test_extra_passes_a_missing_module_of_an_installed_library_unchanged():
    """A dependency *of* an optional library missing is a broken install, not a missing extra."""
    with pytest.raises(ModuleNotFoundError) as raised, extra("export"):
        raise ModuleNotFoundError("No module named 'lxml'", name="lxml")
    assert not isinstance(raised.value, UserInputError)


def test_extra_names_the_package_of_a_missing_submodule():
    with pytest.raises(MissingExtraError, match=re.escape("(commonroad-io is not installed)")), extra("export"):
        raise ModuleNotFoundError("No module named 'commonroad.scenario'", name="commonroad.scenario")


def test_extra_refuses_an_unknown_name():
    with pytest.raises(ValueError, match="unknown extra 'videos'"), extra("videos"):
        pass


def test_the_extras_are_the_ones_pyproject_declares():
    """vrusim/extras.py and [project.optional-dependencies] name the same extras and packages; `all` is all of
    them, and `test` installs `all`."""
    project = tomllib.loads((REPO_ROOT / "pyproject.toml").read_text())["project"]
    optional = project["optional-dependencies"]

    def names(requirements: list[str]) -> set[str]:
        return {re.match(r"[A-Za-z0-9_.\-]+(\[[^\]]*\])?", r).group(0).lower() for r in requirements}

    assert set(optional) == {*EXTRAS, "all", "test"}
    for name, declared in EXTRAS.items():
        assert names(optional[name]) == set(declared.packages.values()), name
    assert names(optional["all"]) == {f"vrusim[{','.join(sorted(EXTRAS, key=list(optional).index))}]"}
    assert "vrusim[all]" in names(optional["test"])
    core = names(project["dependencies"])
    assert core.isdisjoint(p for e in EXTRAS.values() for p in e.packages.values())
    assert core.isdisjoint({"scipy", "imageio", "psutil"})


# ------------------------------------------------------------------------------------------- the core


BLOCKER = """
import importlib, pkgutil, sys

class Uninstalled:
    def find_spec(self, name, path=None, target=None):
        if name.partition(".")[0] in {blocked}:
            raise ModuleNotFoundError(f"No module named {{name!r}}", name=name)

sys.meta_path.insert(0, Uninstalled())
import vrusim
modules = [m.name for m in pkgutil.walk_packages(vrusim.__path__, "vrusim.")
           if not m.name.startswith({adapters}) and not m.name.endswith("__main__")]
for name in modules:
    importlib.import_module(name)
{after}
print(len(modules))
"""


def run_without_extras(after: str = "") -> subprocess.CompletedProcess:
    code = BLOCKER.format(blocked=set(NOT_CORE), adapters=ADAPTERS, after=after)
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=False, timeout=300)


def test_every_core_module_imports_without_any_optional_library():
    """Each module outside the adapter packages imports with every extra's library (and SciPy, imageio,
    psutil, pandas) uninstalled, and a correlated sweep design (the Gaussian copula, once SciPy's) is drawn."""
    correlated = """
from pathlib import Path
from vrusim.sweep.design import make_design
from vrusim.sweep.plan import make_plan
from vrusim.sweep.spec import spec_from_mapping
spec = spec_from_mapping({"base": BASE, "samples": 100, "parameters": {
    "ego.cruise_speed_mps": {"uniform": [10, 20]},
    "vrus[0].top_speed_mps": {"truncated_normal": {"mean": 1.5, "std": 0.5, "low": 1.0, "high": 3.0}}},
    "correlation": [{"between": ["ego.cruise_speed_mps", "vrus[0].top_speed_mps"], "rho": 0.6}]},
    "spec.yaml", Path("."))
assert len(make_design(make_plan(spec))["vrus[0].top_speed_mps"]) == 100
""".replace("BASE", repr(str(PEDESTRIAN)))
    done = run_without_extras(correlated)
    assert done.returncode == 0, done.stderr
    assert int(done.stdout.split()[-1]) > 100  # modules imported


def test_the_core_check_catches_an_optional_import():
    """The check above can fail: a core module importing an optional library breaks it."""
    done = run_without_extras("import gymnasium")
    assert done.returncode != 0
    assert "No module named 'gymnasium'" in done.stderr


def test_the_installed_requirements_hold():
    """`pip check` passes in the environment running the tests (README's test command: every extra, the test
    tools; the ASAM checkers in a venv of their own, tests/asam_qc.py)."""
    pip = subprocess.run([sys.executable, "-m", "pip", "--version"], capture_output=True, check=False)
    if pip.returncode != 0:
        pytest.skip("this environment has no pip")
    done = subprocess.run(
        [sys.executable, "-m", "pip", "check"], capture_output=True, text=True, check=False, timeout=300
    )
    assert done.returncode == 0, done.stdout + done.stderr
