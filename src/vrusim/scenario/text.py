"""Free-text fields (a scenario's name and description, an obstacle's label): text every output can carry.

A name reaches file names, terminal tables, figures, XML (OpenSCENARIO, CommonRoad) and HTML, where a control
character or a lone surrogate (YAML's `"\\x01"`, `"\\ud800"`) would break the output after the run: XML has no
way to write them, a font cannot draw them. They are refused when the scenario is read, naming the field.
`OneLineText` takes no control character at all, `Text` tabs and line breaks (a description of several lines).
"""

from __future__ import annotations

import unicodedata
from typing import Annotated, Any

from pydantic import BeforeValidator

_NOT_CHARACTERS = frozenset({"\ufffe", "\uffff"})
"""Code points that are no characters (no XML document may hold them)."""


def _misfit(text: str, allowed: str) -> str | None:
    """Why `text` cannot be written everywhere (its first bad code point and where), or None."""
    if text.isascii() and text.isprintable():
        return None
    for index, char in enumerate(text):
        if char in allowed:
            continue
        category = unicodedata.category(char)
        if category == "Cc":
            what = "the control character"
        elif category == "Cs":
            what = "a lone surrogate"
        elif char in _NOT_CHARACTERS:
            what = "the non-character"
        else:
            continue
        return f"contains {what} U+{ord(char):04X} (character {index + 1})"
    return None


def one_line_text(text: Any) -> Any:
    """`text` if it holds no control character (tab and line break included), surrogate or non-character (a
    value that is no string is left to the type check)."""
    reason = _misfit(text, "") if isinstance(text, str) else None
    if reason is not None:
        raise ValueError(f"{reason}; expected one line of printable text")
    return text


def free_text(text: Any) -> Any:
    """`text` if it holds no control character other than tab and line break, surrogate or non-character."""
    reason = _misfit(text, "\t\n") if isinstance(text, str) else None
    if reason is not None:
        raise ValueError(f"{reason}; expected printable text, tabs and line breaks")
    return text


OneLineText = Annotated[str, BeforeValidator(one_line_text)]
"""A name or label: printable text on one line."""
Text = Annotated[str, BeforeValidator(free_text)]
"""A description: printable text, tabs and line breaks."""
