"""Figure text drawn as written: user text (a scenario name, a description, a test id, a planner name) reaches
matplotlib titles, labels and legends, where a `$` would start mathtext (`A$$B` fails to parse; `$x$` turns
into math) and a character the font lacks prints a warning to stderr. vrusim draws no math, so every figure is
drawn with mathtext off and those glyph warnings silenced (the character is drawn as a box): `drawing(fig)`
around each draw, `literal_texts(fig)` in the builders whose figures callers may save themselves."""

from __future__ import annotations

import warnings
from collections.abc import Iterator
from contextlib import contextmanager
from typing import TypeVar

from matplotlib import rc_context
from matplotlib.figure import Figure, SubFigure
from matplotlib.text import Text

MISSING_GLYPH_WARNING = r"Glyph \d+ .*missing from font"
"""Start of matplotlib's warning about a character its font cannot draw (a regular expression)."""

F = TypeVar("F", Figure, SubFigure)


def literal_texts(fig: F) -> F:
    """`fig`, with every text now in it set to draw literally (a `$` is a dollar sign, not mathtext)."""
    for text in fig.findobj(Text):
        text.set_parse_math(False)
    return fig


@contextmanager
def quiet_text() -> Iterator[None]:
    """While drawing: texts created meanwhile (tick labels) literal too, and no missing-glyph warnings."""
    with rc_context({"text.parse_math": False}), warnings.catch_warnings():
        warnings.filterwarnings("ignore", message=MISSING_GLYPH_WARNING, category=UserWarning)
        yield


@contextmanager
def drawing(fig: Figure | SubFigure) -> Iterator[None]:
    """Around drawing or saving `fig`: its texts literal (`literal_texts`), and `quiet_text`."""
    literal_texts(fig)
    with quiet_text():
        yield
