"""The README's package layout is written from the code (docs/make_layout.py) and the contract covers the package."""

from __future__ import annotations

import importlib.util
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def _make_layout():
    spec = importlib.util.spec_from_file_location("make_layout", ROOT / "docs" / "make_layout.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_readme_layout_is_what_the_code_says():
    done = subprocess.run([sys.executable, "docs/make_layout.py", "--check"], cwd=ROOT, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr


def test_layout_check_fails_on_a_drifted_readme():
    make_layout = _make_layout()
    readme = (ROOT / "README.md").read_text()
    drifted = readme.replace("  geometry/ ", "  gone.py     A module that is not there.\n  geometry/ ", 1)
    assert drifted != readme
    assert make_layout.rewritten(drifted) == readme


def test_every_top_level_module_and_package_is_in_a_layer():
    """A new package or top-level module must be placed in the layers contract, or the layout and check miss it."""
    named = set(_make_layout()._layer_names())
    package = ROOT / "src" / "vrusim"
    present = {f"vrusim.{p.stem}" for p in package.glob("*.py") if p.stem not in ("__init__", "__main__")}
    present |= {f"vrusim.{p.name}" for p in package.iterdir() if (p / "__init__.py").exists()}
    assert present - named == set()
