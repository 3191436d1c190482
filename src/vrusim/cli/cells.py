"""How values appear in the cells of the terminal tables: numbers with units, ticks, on / off."""

from __future__ import annotations

MISSING = "—"
"""A value that does not exist (no contact, no detection)."""


def number(value: float | None, unit: str = "", digits: int = 2) -> str:
    """`value` with `digits` decimals and its unit; a dash for None."""
    if value is None:
        return MISSING
    text = f"{value:.{digits}f}"
    return f"{text} {unit}" if unit else text


def mark(ok: bool) -> str:
    """A green tick or a red cross."""
    return "[green]✓[/]" if ok else "[red]✗[/]"


def on_off(enabled: bool) -> str:
    """A switch as on / off."""
    return "on" if enabled else "off"
