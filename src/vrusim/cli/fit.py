"""Tables that fit the terminal (80 columns and up) by wrapping at spaces, not by cutting words with "…".

Rich narrows a table that is too wide by shrinking its wrappable columns evenly, without regard to the longest
word of each, so a column of codes or numbers next to a column of prose gets cut. `fit_table` narrows the widest
wrappable column first and never below its longest word, then fixes those widths for Rich.
"""

from __future__ import annotations

from rich.console import Console, Group, RenderableType
from rich.measure import Measurement
from rich.table import Column, Table

NATURAL_WIDTH = 10_000
"""Width at which no table needs wrapping (to measure a table's natural width)."""


def _word_and_line(console: Console, column: Column) -> tuple[int, int]:
    """Longest word and longest line of a column's header and cells (without padding)."""
    options = console.options.update_width(NATURAL_WIDTH)
    measures = [Measurement.get(console, options, cell) for cell in (column.header, *column.cells)]
    return max(m.minimum for m in measures), max(m.maximum for m in measures)


def natural_width(table: Table, console: Console) -> int:
    """The width `table` takes without wrapping, in characters."""
    return console.measure(table, options=console.options.update_width(NATURAL_WIDTH)).maximum


def _narrow(table: Table, console: Console, ranges: list[tuple[int, int]], free: list[int]) -> int:
    """Narrow the `free` columns, the widest first and none below its longest word, as far as needed; fix their
    widths on the table and return the width still missing (0: it fits)."""
    for index in free:
        table.columns[index].width = None
    excess = natural_width(table, console) - console.width
    widths = [line for _, line in ranges]
    while excess > 0:
        candidates = [index for index in free if widths[index] > ranges[index][0]]
        if not candidates:
            break
        widest = max(candidates, key=lambda index: widths[index])
        widths[widest] -= 1
        excess -= 1
    for index in free:
        table.columns[index].width = widths[index] if widths[index] < ranges[index][1] else None
    return max(excess, 0)


def fit_table(table: Table, console: Console) -> Table:
    """Narrow the wrappable columns of `table` until it fits `console` (the widest first, none below its longest
    word); if that is not enough, one space between columns instead of two and none at the edges. A table that
    still cannot fit is left to Rich. Returns `table`."""
    if natural_width(table, console) <= console.width:
        return table
    ranges = [_word_and_line(console, column) for column in table.columns]
    free = [
        index
        for index, column in enumerate(table.columns)
        if column.width is None and not column.no_wrap and ranges[index][0] < ranges[index][1]
    ]
    if _narrow(table, console, ranges, free):
        table.collapse_padding = True
        table.pad_edge = False
        _narrow(table, console, ranges, free)
    return table


def fitted(renderable: RenderableType, console: Console) -> RenderableType:
    """`renderable` with every table in it (also inside a Group) fitted to `console`."""
    if isinstance(renderable, Table):
        return fit_table(renderable, console)
    if isinstance(renderable, Group):
        for part in renderable.renderables:
            fitted(part, console)
    return renderable
