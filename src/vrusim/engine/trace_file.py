"""Per-step trace files of a run: one row per time step, CSV or Parquet chosen by the file suffix.

Columns: t_s, the ego state and command, the planner mode (by name), the closest clearance and the smallest
time-to-collision (null when infinite), then per VRU k: vru{k}_x_m, vru{k}_y_m, vru{k}_speed_mps,
vru{k}_detected, vru{k}_source (bitmask: 1 sensor, 2 V2X) and vru{k}_v2x_age_s (age of the V2X message the ego
holds about the VRU, s; null when none). Absent or infinite values are written as null (an empty CSV field), never
NaN. Files are written atomically: to a temporary file in the same folder, then renamed over the target, so a
failure never leaves a half-written file behind. `read_trace` reads one back as trace arrays.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.csv as pa_csv
import pyarrow.parquet as pq

from vrusim.engine.simulate import BatchRun
from vrusim.errors import UserInputError
from vrusim.io.atomic import write_atomically

TRACE_SUFFIXES = (".csv", ".parquet")
"""Supported trace file suffixes (case-insensitive)."""

EGO_COLUMNS = (
    "ego_x_m",
    "ego_y_m",
    "ego_speed_mps",
    "ego_accel_mps2",
    "ego_command_mps2",
    "ego_curvature_per_m",
    "ego_station_m",
)


def trace_format(path: str | Path) -> str:
    """'csv' or 'parquet' from the file suffix; UserInputError for anything else."""
    suffix = Path(path).suffix.lower()
    if suffix not in TRACE_SUFFIXES:
        shown = f"'{Path(path).suffix}'" if Path(path).suffix else "no suffix"
        raise UserInputError(f"{path}: unsupported trace file type ({shown}); use a .csv or .parquet file name")
    return suffix.removeprefix(".")


def check_trace_path(path: str | Path) -> str:
    """Validate a trace file name before any work: its suffix and its folder. Returns 'csv' or 'parquet'."""
    path = Path(path)
    kind = trace_format(path)
    if not path.parent.is_dir():
        raise UserInputError(f"{path}: cannot write trace, folder {path.parent} does not exist")
    if path.is_dir():
        raise UserInputError(f"{path}: cannot write trace, it is a folder")
    return kind


def _floats(values: np.ndarray) -> pa.Array:
    """Float column with every NaN or infinity turned into null."""
    values = np.asarray(values, dtype=float)
    return pa.array(values, type=pa.float64(), mask=~np.isfinite(values))


def trace_table(run: BatchRun, variant: int = 0) -> pa.Table:
    """The trace of one variant of a run as an Arrow table, one row per step."""
    trace = run.trace
    if trace is None:
        raise ValueError("this run has no trace: simulate(..., trace=True)")
    if not 0 <= variant < run.params.size:
        raise ValueError(f"variant {variant} out of range for a batch of {run.params.size}")
    b = variant
    columns: dict[str, pa.Array] = {"t_s": _floats(np.round(trace["t_s"], 9))}
    for name in EGO_COLUMNS[:2]:
        columns[name] = _floats(trace[name][:, b])
    heading = np.degrees(np.arctan2(trace["ego_heading_y"][:, b], trace["ego_heading_x"][:, b]))
    columns["ego_heading_deg"] = _floats(heading)
    for name in EGO_COLUMNS[2:]:
        columns[name] = _floats(trace[name][:, b])
    modes = np.asarray(trace["planner_mode"][:, b], dtype=int)
    names = list(run.mode_names)
    columns["planner_mode"] = pa.array(
        [names[m] if 0 <= m < len(names) else str(m) for m in modes.tolist()], type=pa.string()
    )
    columns["clearance_m"] = _floats(trace["clearance_m"][:, b])
    columns["ttc_s"] = _floats(trace["ttc_s"][:, b])
    valid = np.asarray(run.params.vru_valid[b], dtype=bool)
    for k in np.flatnonzero(valid).tolist():
        columns[f"vru{k}_x_m"] = _floats(trace["vru_x_m"][:, b, k])
        columns[f"vru{k}_y_m"] = _floats(trace["vru_y_m"][:, b, k])
        columns[f"vru{k}_speed_mps"] = _floats(trace["vru_speed_mps"][:, b, k])
        columns[f"vru{k}_detected"] = pa.array(np.asarray(trace["vru_detected"][:, b, k], dtype=bool))
        columns[f"vru{k}_source"] = pa.array(np.asarray(trace["vru_source"][:, b, k], dtype=np.int8))
        columns[f"vru{k}_v2x_age_s"] = _floats(trace["vru_v2x_age_s"][:, b, k])
    return pa.table(columns)


def write_trace(run: BatchRun, path: str | Path, variant: int = 0) -> int:
    """Write the per-step trace of `variant` to `path` (.csv or .parquet), atomically; return the row count.

    Raises UserInputError (naming the file) for an unsupported suffix or when the file cannot be written.
    """
    path = Path(path)
    kind = check_trace_path(path)
    table = trace_table(run, variant)
    if kind == "csv":
        write_atomically(path, lambda temp: pa_csv.write_csv(table, temp), "trace")
    else:
        write_atomically(path, lambda temp: pq.write_table(table, temp), "trace")
    return table.num_rows


MAX_MODES = int(np.iinfo(np.int8).max)
"""Most planner modes a trace can name (the engine records a mode as an int8)."""
NULLABLE = ("ttc_s", "clearance_m", "v2x_age_s")
"""Columns (ending in these names) a trace may leave empty: no time-to-collision, no V2X message held."""


def _place(path: Path, row: int) -> str:
    """Where row `row` (from 0) of a trace file is: its line in a CSV file (after the header), else its row."""
    return f"line {row + 2}" if trace_format(path) == "csv" else f"row {row + 1}"


def _column(table: pa.Table, name: str, path: Path) -> pa.ChunkedArray:
    if name not in table.column_names:
        raise UserInputError(f"{path} has no column {name!r}; expected a trace written by `vrusim run --trace`")
    return table.column(name)


def _read_list(table: pa.Table, name: str, path: Path) -> list:
    return _column(table, name, path).to_pylist()


def _parsed(column: pa.ChunkedArray, name: str, path: Path) -> np.ndarray:
    """A column of text (CSV cells pyarrow could not all read as numbers) as floats (empty: NaN, "nan": inf);
    UserInputError naming the line of the first cell that is no number."""
    values = np.full(len(column), np.nan)
    for row, value in enumerate(column.to_pylist()):
        text = "" if value is None else str(value).strip().lower()
        if name.endswith("_detected") and text in ("true", "false"):
            values[row] = float(text == "true")
        elif text:
            try:
                number = float(text)
            except ValueError:
                expected = "true or false" if name.endswith("_detected") else "a number"
                raise UserInputError(
                    f"{path}: {_place(path, row)}, column {name}: {value!r} is not {expected}"
                ) from None
            values[row] = np.inf if np.isnan(number) else number
    return values


def _read_column(table: pa.Table, name: str, path: Path) -> np.ndarray:
    """A column as floats (empty: NaN); UserInputError naming the line and column of a cell that is no finite
    number, an empty cell where the column needs a value (all but NULLABLE), or a VRU source other than 0-3."""
    column = _column(table, name, path)
    kind = column.type
    if pa.types.is_integer(kind) or pa.types.is_floating(kind) or pa.types.is_boolean(kind):
        values = np.array(pc.cast(column, pa.float64()).fill_null(np.inf).to_numpy(), dtype=float)
        values[np.isnan(values)] = np.inf  # a NaN stored as a number is no empty cell
        values[np.asarray(column.is_null().to_numpy(zero_copy_only=False), dtype=bool)] = np.nan
    elif pa.types.is_null(kind):
        values = np.full(len(column), np.nan)
    else:
        values = _parsed(column, name, path)
    problems = [(np.isinf(values), "is not a finite number")]
    if not name.endswith(NULLABLE):
        problems.append((np.isnan(values), "has no value (an empty cell or nan); expected a finite number"))
    if name.endswith("_source"):
        problems.append((np.isfinite(values) & ~np.isin(values, (0, 1, 2, 3)), "is not 0, 1, 2 or 3"))
    for bad, problem in problems:
        if bad.any():
            row = int(np.argmax(bad))
            cell = column[row].as_py()
            raise UserInputError(
                f"{path}: {_place(path, row)}, column {name}: {'' if cell is None else repr(cell) + ' '}{problem}"
            )
    return values


def read_trace(path: Path, vru_count: int) -> tuple[dict[str, np.ndarray], tuple[str, ...]]:
    """A trace file of `write_trace` read back: the trace arrays of its one variant as the engine records them
    ([T], per VRU [T, K]; null is NaN, a null TTC infinite) and the planner's mode names in order of appearance.
    A file written before vru{k}_v2x_age_s existed gets NaN there. UserInputError naming the file when it cannot
    be read, lacks a column, holds no rows or has no columns for `vru_count` VRUs, and naming the line (CSV) or
    row (Parquet) and column of a cell that is no finite number or is empty where a number is needed.
    """
    try:
        data = pq.read_table(path) if trace_format(path) == "parquet" else pa_csv.read_csv(path)
    except (OSError, pa.ArrowException) as error:
        raise UserInputError(f"cannot read trace {path} ({error})") from None
    table = data
    if any(f"vru{k}_x_m" not in table.column_names for k in range(vru_count)):
        raise UserInputError(f"{path} has no columns of {vru_count} VRUs (vru0_x_m ... vru{vru_count - 1}_x_m)")
    if "t_s" not in table.column_names or table.num_rows == 0:
        raise UserInputError(f"{path} holds no trace rows")
    rows = table.num_rows
    heading = np.radians(_read_column(table, "ego_heading_deg", path))
    names = tuple(dict.fromkeys(str(m) for m in _read_list(table, "planner_mode", path)))
    if len(names) > MAX_MODES:
        raise UserInputError(
            f"{path}: column planner_mode names {len(names):,} modes; a planner has at most {MAX_MODES}"
        )
    trace = {
        "t_s": _read_column(table, "t_s", path),
        "ego_heading_x": np.cos(heading),
        "ego_heading_y": np.sin(heading),
        "planner_mode": np.array([names.index(str(m)) for m in _read_list(table, "planner_mode", path)], np.int8),
    }
    for name in (*EGO_COLUMNS, "clearance_m"):
        trace[name] = _read_column(table, name, path)
    ttc = _read_column(table, "ttc_s", path)
    trace["ttc_s"] = np.where(np.isnan(ttc), np.inf, ttc)

    def per_vru(column: str, absent: float | None = None) -> np.ndarray:
        values = [
            np.full(rows, absent) if absent is not None and f"vru{k}_{column}" not in table.column_names
            else _read_column(table, f"vru{k}_{column}", path)
            for k in range(vru_count)
        ]  # fmt: skip
        return np.stack(values, axis=1) if values else np.empty((rows, 0))

    trace["vru_x_m"], trace["vru_y_m"] = per_vru("x_m"), per_vru("y_m")
    trace["vru_speed_mps"] = per_vru("speed_mps")
    trace["vru_detected"] = per_vru("detected") > 0.5
    trace["vru_source"] = per_vru("source").astype(np.int8)
    trace["vru_v2x_age_s"] = per_vru("v2x_age_s", absent=np.nan)
    return trace, names
