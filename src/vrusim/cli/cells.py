"""How values appear in the cells of the terminal tables: numbers with units, ticks, on / off."""

from __future__ import annotations

__all__ = ["mark", "number", "on_off"]


def number(value: float | None, unit: str = "", digits: int = 2) -> str:
    """A value with its unit, fixed decimals; "—" when absent (`vrusim.metrics.display.number`, imported when
    first used: the metric catalogue loads the engine)."""
    from vrusim.metrics.display import number

    return number(value, unit, digits)


def mark(ok: bool) -> str:
    """A green tick or a red cross."""
    return "[green]✓[/]" if ok else "[red]✗[/]"


def on_off(enabled: bool) -> str:
    """A switch as on / off."""
    return "on" if enabled else "off"
