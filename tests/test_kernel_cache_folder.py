"""Where compiled kernels are cached: the user's cache folder keyed by the source version; a private folder in the
temporary folder when that cannot be written (a read-only home); no cache at all, rather than an error, when
neither can be, or when the temporary one is not this user's alone (cached kernels are pickled code)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

import vrusim
from vrusim.version import source_digest

SRC = Path(vrusim.__file__).resolve().parents[1]

_PROBE = """
import json
import vrusim.kernels as kernels
from vrusim import kernel_notices

def twice(x):
    return 2.0 * x

kernel = kernels.njit(cache=True)(twice)
print(json.dumps({
    "folder": None if kernels.kernel_cache_folder() is None else str(kernels.kernel_cache_folder()),
    "numba_folder": kernels.numba.config.CACHE_DIR,
    "cached": type(kernel._cache).__name__ != "NullCache",
    "notice_says_uncached": kernel_notices._uncached,
    "result": kernel(1.5),
}))
"""


def _probe(tmp_path: Path, cache_home: Path, **env: str) -> dict:
    """The probe in a fresh process whose cache home is `cache_home` and temporary folder `tmp_path / "tmp"`."""
    temporary = tmp_path / "tmp"
    temporary.mkdir(exist_ok=True)
    env = {key: value for key, value in os.environ.items() if key != "NUMBA_CACHE_DIR"} | env
    env |= {"XDG_CACHE_HOME": str(cache_home), "TMPDIR": str(temporary), "PYTHONPATH": str(SRC)}
    probe = tmp_path / "probe.py"  # a file: numba caches only functions with a source file
    probe.write_text(_PROBE)
    done = subprocess.run(
        [sys.executable, str(probe)], env=env, cwd=tmp_path, capture_output=True, text=True, timeout=120
    )
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


def _private(tmp_path: Path) -> Path:
    return tmp_path / "tmp" / f"vrusim-{os.getuid()}"


def test_the_users_cache_folder_keyed_by_the_source_version(tmp_path):
    report = _probe(tmp_path, tmp_path / "cache")
    expected = tmp_path / "cache" / "vrusim" / "kernels" / source_digest()[:16]
    assert report["folder"] == report["numba_folder"] == str(expected)
    assert report["cached"] and not report["notice_says_uncached"] and report["result"] == 3.0
    assert any(expected.rglob("*.nbi"))  # the probe's kernel was cached there
    assert not _private(tmp_path).exists()


def test_an_unwritable_cache_home_falls_back_to_a_private_temporary_folder(tmp_path):
    not_a_folder = tmp_path / "file"
    not_a_folder.write_text("a file where the cache home should be")
    report = _probe(tmp_path, not_a_folder)
    expected = _private(tmp_path) / "kernels" / source_digest()[:16]
    assert report["folder"] == report["numba_folder"] == str(expected)
    assert report["cached"] and report["result"] == 3.0
    assert _private(tmp_path).stat().st_mode & 0o777 == 0o700
    assert any(expected.rglob("*.nbi"))


@pytest.mark.parametrize("planted", ["open to others", "a symbolic link"])
def test_a_temporary_folder_that_is_not_private_is_not_used(tmp_path, planted):
    """Another user could put pickled code there: the kernels then compile uncached, which numba alone would refuse
    where it finds no writable folder."""
    not_a_folder = tmp_path / "file"
    not_a_folder.write_text("x")
    (tmp_path / "tmp").mkdir()
    if planted == "open to others":
        _private(tmp_path).mkdir()
        _private(tmp_path).chmod(0o777)
    else:
        (tmp_path / "elsewhere").mkdir(mode=0o700)
        _private(tmp_path).symlink_to(tmp_path / "elsewhere")
    report = _probe(tmp_path, not_a_folder)
    assert report["folder"] is None
    assert not report["cached"] and report["notice_says_uncached"]
    assert report["result"] == 3.0
    assert not list(tmp_path.rglob("*.nbi"))  # nowhere: not in the probe's own __pycache__ either


def test_a_numba_cache_dir_that_cannot_be_written_compiles_uncached(tmp_path):
    not_a_folder = tmp_path / "file"
    not_a_folder.write_text("x")
    report = _probe(tmp_path, tmp_path / "cache", NUMBA_CACHE_DIR=str(not_a_folder / "kernels"))
    assert report["folder"] is None and report["numba_folder"] == str(not_a_folder / "kernels")
    assert not report["cached"] and report["notice_says_uncached"] and report["result"] == 3.0
    assert not list(tmp_path.rglob("*.nbi"))


def test_a_numba_cache_dir_that_can_be_written_is_used(tmp_path):
    report = _probe(tmp_path, tmp_path / "cache", NUMBA_CACHE_DIR=str(tmp_path / "chosen"))
    assert report["folder"] is None and report["numba_folder"] == str(tmp_path / "chosen")
    assert report["cached"] and not report["notice_says_uncached"]
    assert any((tmp_path / "chosen").rglob("*.nbi"))
