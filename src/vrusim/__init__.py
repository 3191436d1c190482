"""vrusim: closed-loop simulation of vulnerable-road-user safety tests."""

from __future__ import annotations

import hashlib
import os
import sys
from pathlib import Path

__version__ = "0.1.0"


def _configure_kernel_cache() -> None:
    """Keep compiled kernels in a cache folder keyed by a hash of this package's source.

    Numba checks only a kernel's own file when reusing cached machine code; kernels inline helpers from other
    modules, so a change there could otherwise run stale code. A user-set NUMBA_CACHE_DIR is respected.
    """
    if "NUMBA_CACHE_DIR" in os.environ:
        return
    digest = hashlib.sha256()
    for path in sorted(Path(__file__).parent.rglob("*.py")):
        digest.update(path.read_bytes())
    base = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")
    folder = str(base / "vrusim" / "kernels" / digest.hexdigest()[:16])
    os.environ["NUMBA_CACHE_DIR"] = folder
    if "numba" in sys.modules:  # numba already configured itself: tell it too
        sys.modules["numba"].config.CACHE_DIR = folder


_configure_kernel_cache()
