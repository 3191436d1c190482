"""Safe HTML building: everything is escaped unless it is already `Html`; tables whose every cell carries its value.

`tag("td", value)` escapes `value`; `Html` marks text that is already markup (only this module and the element
builders create it). Table cells carry `data-col` and `data-value` (the exact value as JSON), rows `data-row`,
so tests and scripts read numbers without parsing the displayed text.
"""

from __future__ import annotations

import html
import json
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any


class Html(str):
    """Text that is already HTML: inserted as is; `Html + x` escapes `x` unless it is Html too."""

    __slots__ = ()

    def __add__(self, other: object) -> Html:
        return Html(str.__add__(self, esc(other)))


def esc(value: Any) -> Html:
    """`value` as HTML: Html unchanged, anything else escaped (quotes too)."""
    if isinstance(value, Html):
        return value
    return Html(html.escape(str(value), quote=True))


def join(parts: Iterable[Any]) -> Html:
    """Concatenate, escaping every part that is not Html."""
    return Html("".join(esc(part) for part in parts if part is not None))


def attributes(attrs: dict[str, Any]) -> str:
    """` name="value"` pairs; `class_` → class, `data_x` → data-x; None and False are left out, True is bare."""
    out = []
    for name, value in attrs.items():
        if value is None or value is False:
            continue
        name = name.rstrip("_").replace("_", "-")
        out.append(f" {name}" if value is True else f' {name}="{html.escape(str(value), quote=True)}"')
    return "".join(out)


def tag(name: str, *children: Any, **attrs: Any) -> Html:
    """`<name attrs>children</name>` with the children escaped unless Html."""
    return Html(f"<{name}{attributes(attrs)}>{join(children)}</{name}>")


def void(name: str, **attrs: Any) -> Html:
    """An element without content (`<img ...>`, `<input ...>`)."""
    return Html(f"<{name}{attributes(attrs)}>")


def json_value(value: Any) -> str:
    """A cell's exact value as JSON (floats round-trip; NaN and infinities as null)."""
    if isinstance(value, float) and not math.isfinite(value):
        value = None
    return json.dumps(value, allow_nan=False, separators=(",", ":"))


def script_json(document: Any, element_id: str | None = None, class_: str | None = None) -> Html:
    """A `<script type="application/json">` block; `<`, `>` and `&` are \\u-escaped so no text can close it."""
    text = json.dumps(document, allow_nan=False, separators=(",", ":"), default=str)
    text = text.replace("<", "\\u003c").replace(">", "\\u003e").replace("&", "\\u0026")
    return Html(f'<script type="application/json"{attributes({"id": element_id, "class_": class_})}>{text}</script>')


# ----------------------------------------------------------------------------------------------- tables


@dataclass(frozen=True)
class Column:
    """A table column: `key` names the value in each row (and becomes data-col); `digits` None: text."""

    key: str
    title: str
    digits: int | None = None
    unit: str = ""


def display(value: Any, digits: int | None = None, unit: str = "") -> str:
    """How a value is shown: "—" for missing, yes/no, a number with `digits` decimals and its unit, or text."""
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "—" if value is None or math.isnan(value) else ("∞" if value > 0 else "−∞")
    if isinstance(value, bool):
        return "yes" if value else "no"
    if digits is not None and isinstance(value, int | float):
        text = f"{value:.{digits}f}"
        if text.startswith("-") and float(text) == 0.0:
            text = text[1:]
        return f"{text} {unit}" if unit else text
    return f"{value} {unit}" if unit else str(value)


def cell(key: str, value: Any, digits: int | None = None, unit: str = "", shown: Any = None, **attrs: Any) -> Html:
    """A `<td>` with data-col and data-value; numbers right-aligned; `shown` overrides the displayed text."""
    numeric = isinstance(value, int | float) and not isinstance(value, bool)
    classes = " ".join(filter(None, ["num" if numeric else None, attrs.pop("class_", None)]))
    text = display(value, digits, unit) if shown is None else shown
    digits_attr = digits if numeric and digits is not None and shown is None else None
    return tag(
        "td", text, class_=classes or None, data_col=key, data_value=json_value(value), data_digits=digits_attr, **attrs
    )


def table(
    element_id: str,
    columns: Sequence[Column],
    rows: Sequence[tuple[str, dict[str, Any]]],
    caption: str | None = None,
    row_header: Column | None = None,
    classes: dict[tuple[str, str], str] | None = None,
    totals: Sequence[tuple[str, dict[str, Any]]] = (),
) -> Html:
    """A sortable data table: `rows` are (row key, values by column key); `row_header` makes the first cell a
    `<th>`; `classes[(row key, column key)]` adds a CSS class to a cell (good / bad); `totals` rows stay last."""
    classes = classes or {}
    head = tag("thead", tag("tr", *(tag("th", c.title, scope="col") for c in _all(row_header, columns))))
    body = []
    for index, (key, values) in enumerate([*rows, *totals]):
        cells = []
        if row_header is not None:
            cells.append(tag("th", display(values.get(row_header.key)), scope="row", data_col=row_header.key))
        for column in columns:
            value = values.get(column.key)
            cells.append(cell(column.key, value, column.digits, column.unit, class_=classes.get((key, column.key))))
        body.append(tag("tr", *cells, data_row=key, class_="total" if index >= len(rows) else None))
    parts = [head, tag("tbody", *body)]
    if caption:
        parts.insert(0, tag("caption", caption))
    return tag("div", tag("table", *parts, id=element_id, class_="data"), class_="table-wrap")


def _all(row_header: Column | None, columns: Sequence[Column]) -> list[Column]:
    return ([row_header] if row_header is not None else []) + list(columns)


def filter_box(table_id: str, placeholder: str = "Filter rows…") -> Html:
    """A text box that hides the rows of table `table_id` not containing every typed word."""
    return void(
        "input", type="search", class_="filter", data_table=table_id, placeholder=placeholder, aria_label=placeholder
    )


def facts(items: Iterable[tuple[str, Any]], element_id: str | None = None) -> Html:
    """A definition list of (label, value) pairs."""
    parts = []
    for label, value in items:
        parts += [tag("dt", label), tag("dd", value)]
    return tag("dl", *parts, class_="facts", id=element_id)


def pre(text: str, title: str | None = None, open_: bool = False) -> Html:
    """Preformatted text, folded under `title` when given."""
    block = tag("pre", text)
    return tag("details", tag("summary", title), block, open=open_) if title else block
