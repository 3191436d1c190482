"""How values appear in the cells of the terminal tables: numbers with units, ticks, on / off."""

from __future__ import annotations

from vrusim.metrics.display import number

__all__ = ["mark", "number", "on_off"]


def mark(ok: bool) -> str:
    """A green tick or a red cross."""
    return "[green]✓[/]" if ok else "[red]✗[/]"


def on_off(enabled: bool) -> str:
    """A switch as on / off."""
    return "on" if enabled else "off"
