"""vrusim: closed-loop simulation of vulnerable-road-user safety tests."""

from __future__ import annotations

import hashlib
import os
import sys
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


def _configure_kernel_cache() -> None:
    """Keep compiled kernels in a cache folder keyed by a hash of this package's source.

    Numba checks only a kernel's own file when reusing cached machine code; kernels inline helpers from other
    modules, so a change there could otherwise run stale code. A user-set NUMBA_CACHE_DIR is respected.
    """
    if "NUMBA_CACHE_DIR" in os.environ:
        return
    base = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")
    folder = str(base / "vrusim" / "kernels" / source_digest()[:16])
    os.environ["NUMBA_CACHE_DIR"] = folder
    if "numba" in sys.modules:  # numba already configured itself: tell it too
        sys.modules["numba"].config.CACHE_DIR = folder


_configure_kernel_cache()
