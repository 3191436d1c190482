"""Result rows as Arrow tables, pandas DataFrames and short HTML tables (for notebooks).

Rows are the JSON-ready dicts vrusim prints (absent values None). Arrow infers each column's type from its
values; a column (or a nested field) with no value at all gets its declared type, float64 unless told otherwise,
so a table's types do not depend on which events happened in the rows it holds.
"""

from __future__ import annotations

import html
from collections.abc import Iterable, Mapping, Sequence
from typing import TYPE_CHECKING, Any

import pyarrow as pa

from vrusim.extras import extra

if TYPE_CHECKING:
    import pandas

TRANSITION = pa.struct([("t_s", pa.float64()), ("from", pa.string()), ("to", pa.string())])
"""One planner mode transition of a summary row."""

SUMMARY_TYPES: dict[str, pa.DataType] = {
    "impact_side": pa.string(),
    "impact_body_side": pa.string(),
    "impact_vru": pa.int64(),
    "transitions": pa.list_(TRANSITION),
}
"""Types of the summary-row columns that are not float64 when every row leaves them empty (None, [])."""


def _settled(field: pa.Field, types: Mapping[str, pa.DataType]) -> pa.Field:
    """`field` with every null type (no value seen) replaced by its declared type, float64 by default."""
    kind = field.type
    if pa.types.is_null(kind):
        return field.with_type(types.get(field.name, pa.float64()))
    if pa.types.is_struct(kind):
        children = [_settled(kind.field(i), {}) for i in range(kind.num_fields)]
        return field.with_type(pa.struct(children))
    if pa.types.is_list(kind) and pa.types.is_null(kind.value_type):
        return field.with_type(types.get(field.name, pa.list_(pa.float64())))
    return field


def arrow_table(rows: Sequence[Mapping[str, Any]], types: Mapping[str, pa.DataType] | None = None) -> pa.Table:
    """The rows as an Arrow table, one column per key (nested dicts become structs, lists of dicts lists)."""
    table = pa.Table.from_pylist(list(rows))
    schema = pa.schema([_settled(field, types or {}) for field in table.schema])
    return table if schema.equals(table.schema) else table.cast(schema)


def pandas_frame(table: pa.Table) -> pandas.DataFrame:
    """The table as a pandas DataFrame; pandas is the optional `pandas` extra, so its absence is a
    `MissingExtraError` (an ImportError) saying what to install."""
    with extra("pandas"):
        import pandas  # noqa: F401
    return table.to_pandas()


def _cell(value: Any) -> str:
    if value is None:
        return "—"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float):
        return f"{value:.3g}" if abs(value) < 1e-3 and value != 0 else f"{value:.2f}"
    return str(value)


def html_table(rows: Sequence[Mapping[str, Any]], columns: Iterable[str], caption: str, limit: int = 20) -> str:
    """A short HTML table of chosen columns (at most `limit` rows, then how many more) under a caption."""
    names = [name for name in columns if rows and name in rows[0]]
    head = "".join(f"<th>{html.escape(name)}</th>" for name in names)
    body = "".join(
        "<tr>" + "".join(f"<td>{html.escape(_cell(row[name]))}</td>" for name in names) + "</tr>"
        for row in rows[:limit]
    )
    more = f"<p>… {len(rows) - limit} more rows</p>" if len(rows) > limit else ""
    return f"<div><p><b>{html.escape(caption)}</b></p><table><tr>{head}</tr>{body}</table>{more}</div>"
