"""vrusim: closed-loop simulation of vulnerable-road-user safety tests."""

from __future__ import annotations

import hashlib
import os
import shutil
import sys
import time
from pathlib import Path

__version__ = "0.1.0"


def source_digest() -> str:
    """SHA-256 (hex) of this package's Python sources: identifies the code that produced a result."""
    global _SOURCE_DIGEST
    if _SOURCE_DIGEST is None:
        digest = hashlib.sha256()
        for path in sorted(Path(__file__).parent.rglob("*.py")):
            digest.update(path.read_bytes())
        _SOURCE_DIGEST = digest.hexdigest()
    return _SOURCE_DIGEST


_SOURCE_DIGEST: str | None = None

KERNEL_CACHE_UNUSED_DAYS = 7
"""A kernel cache folder of another source version that has not been used for this long is deleted, days."""


def _configure_kernel_cache() -> None:
    """Keep compiled kernels in a cache folder keyed by a hash of this package's source.

    Numba checks only a kernel's own file when reusing cached machine code; kernels inline helpers from other
    modules, so a change there could otherwise run stale code. A user-set NUMBA_CACHE_DIR is respected.
    Every source edit thus starts a new folder; folders of other versions unused for
    `KERNEL_CACHE_UNUSED_DAYS` are deleted (using a folder refreshes its time stamp).
    """
    if "NUMBA_CACHE_DIR" in os.environ:
        return
    root = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "vrusim" / "kernels"
    folder = root / source_digest()[:16]
    os.environ["NUMBA_CACHE_DIR"] = str(folder)
    if "numba" in sys.modules:  # numba already configured itself: tell it too
        sys.modules["numba"].config.CACHE_DIR = str(folder)
    prune_kernel_caches(root, keep=folder.name)


def prune_kernel_caches(root: Path, keep: str, unused_days: float = KERNEL_CACHE_UNUSED_DAYS) -> None:
    """Mark `root/keep` as used now; delete the other folders in `root` unused for `unused_days` (best effort)."""
    try:
        (root / keep).mkdir(parents=True, exist_ok=True)
        os.utime(root / keep)
        oldest = time.time() - unused_days * 86400.0
        for entry in root.iterdir():
            if entry.name != keep and entry.is_dir() and entry.stat().st_mtime < oldest:
                shutil.rmtree(entry, ignore_errors=True)
    except OSError:  # a read-only or shared cache: leave it as it is
        pass


_configure_kernel_cache()
