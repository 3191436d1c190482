"""Sweep columns as Arrow tables with a schema fixed by the design, so every results file has the same types.

Numbers, booleans and strings keep their type; any other design value (a mapping such as a whole channel
specification, a list, a mix of types) is stored as its JSON text. Float NaN (an absent result) becomes NULL.
"""

from __future__ import annotations

import json
from typing import Any

import numpy as np
import pyarrow as pa

from vrusim.metrics.catalog import column_dtype


def result_type(column: str) -> pa.DataType:
    """Arrow type of a result column: its metric's declared dtype (`vrusim.metrics.catalog`)."""
    return pa.type_for_alias(column_dtype(column))


def design_type(values: np.ndarray) -> pa.DataType:
    """Arrow type of a design column: int64, float64, bool, string, or string of JSON text ("json")."""
    if values.dtype.kind == "b":
        return pa.bool_()
    if values.dtype.kind in "iu":
        return pa.int64()
    if values.dtype.kind == "f":
        return pa.float64()
    if all(v is None or isinstance(v, str) for v in values.tolist()):
        return pa.string()
    return pa.large_string()


def design_types(design: dict[str, np.ndarray]) -> dict[str, pa.DataType]:
    """The Arrow type of every design column (large_string marks JSON-encoded values)."""
    return {name: design_type(values) for name, values in design.items()}


def _array(values: Any, kind: pa.DataType) -> pa.Array:
    if kind == pa.large_string():
        return pa.array([json.dumps(v, sort_keys=True) for v in values], type=pa.string())
    if kind == pa.float64():
        floats = np.asarray(values, dtype=float)
        return pa.array(floats, mask=np.isnan(floats), type=kind)
    if isinstance(values, np.ndarray) and values.dtype.kind == "O":
        values = values.tolist()
    return pa.array(values, type=kind)


def chunk_table(rows: dict[str, Any], types: dict[str, pa.DataType], results: dict[str, np.ndarray]) -> pa.Table:
    """Design rows (lists or arrays) then result columns, typed; result floats with NaN become NULL."""
    arrays = {name: _array(values, types[name]) for name, values in rows.items()}
    for name, values in results.items():
        arrays[name] = _array(values, result_type(name))
    return pa.table(arrays)
