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


_NUMPY_TYPES = {pa.float64(): np.float64, pa.int64(): np.int64, pa.int8(): np.int8, pa.int32(): np.int32}


def _numeric(values: np.ndarray, kind: pa.DataType, nulls: np.ndarray | None = None) -> pa.Array:
    """A numeric or boolean array from its buffers (`pa.array` on a NumPy array would import pandas: a second
    per worker process)."""
    if kind == pa.bool_():
        data = pa.py_buffer(np.packbits(values, bitorder="little"))
    else:
        data = pa.py_buffer(np.ascontiguousarray(values, dtype=_NUMPY_TYPES[kind]))
    if nulls is None or not nulls.any():
        return pa.Array.from_buffers(kind, len(values), [None, data], null_count=0)
    validity = pa.py_buffer(np.packbits(~nulls, bitorder="little"))
    return pa.Array.from_buffers(kind, len(values), [validity, data], null_count=int(nulls.sum()))


def _strings(values: list[Any]) -> pa.Array:
    """A string array (None: null) from its buffers, as `_numeric`."""
    encoded = [b"" if v is None else v.encode() for v in values]
    offsets = np.zeros(len(encoded) + 1, dtype=np.int32)
    np.cumsum(np.fromiter(map(len, encoded), dtype=np.int64, count=len(encoded)), out=offsets[1:])
    buffers = [pa.py_buffer(offsets), pa.py_buffer(b"".join(encoded))]
    nulls = np.fromiter((v is None for v in values), dtype=bool, count=len(values))
    if not nulls.any():
        return pa.Array.from_buffers(pa.string(), len(values), [None, *buffers], null_count=0)
    validity = pa.py_buffer(np.packbits(~nulls, bitorder="little"))
    return pa.Array.from_buffers(pa.string(), len(values), [validity, *buffers], null_count=int(nulls.sum()))


def _array(values: Any, kind: pa.DataType) -> pa.Array:
    if kind == pa.large_string():
        return _strings([json.dumps(v, sort_keys=True) for v in values])
    if kind == pa.float64():
        floats = np.asarray(values, dtype=float)
        return _numeric(floats, kind, np.isnan(floats))
    if isinstance(values, np.ndarray) and (
        (kind in _NUMPY_TYPES and values.dtype == _NUMPY_TYPES[kind]) or (kind == pa.bool_() and values.dtype == bool)
    ):
        return _numeric(values, kind)
    if isinstance(values, np.ndarray) and values.dtype.kind == "O":
        values = values.tolist()
    if kind == pa.string() and all(v is None or isinstance(v, str) for v in values):
        return _strings(list(values))
    return pa.array(values, type=kind)


def chunk_table(rows: dict[str, Any], types: dict[str, pa.DataType], results: dict[str, np.ndarray]) -> pa.Table:
    """Design rows (lists or arrays) then result columns, typed; result floats with NaN become NULL."""
    arrays = {name: _array(values, types[name]) for name, values in rows.items()}
    for name, values in results.items():
        arrays[name] = _array(values, result_type(name))
    return pa.table(arrays)
