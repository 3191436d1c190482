"""vrusim: closed-loop simulation of vulnerable-road-user safety tests."""

from __future__ import annotations

from vrusim.version import __version__

__all__ = ["__version__"]
