"""Euro NCAP cell colours shared by the scorecards (PNG, terminal, HTML) of both editions."""

from __future__ import annotations

COLOUR_HEX: dict[str, str] = {
    "green": "#3aa845",
    "yellow": "#f7d117",
    "orange": "#f39c12",
    "brown": "#8e5b2f",
    "red": "#d62b2b",
    "untested": "#cfcfcf",
}
"""Cell fill per Euro NCAP colour; "untested" for grid cells without a test."""
LIGHT_TEXT = ("brown", "red")
"""Colours whose cells take white text."""


def ink(colour: str) -> str:
    """Text colour on a cell of `colour`."""
    return "white" if colour in LIGHT_TEXT else "black"
