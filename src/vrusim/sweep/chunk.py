"""One batch of a sweep, as run by a worker: build its variants, simulate them, return one table row each.

Variants of one batch that use different planners or time steps run as separate sub-batches (one engine
batch runs one planner at one dt); rows come back in variant order either way. A variant's results do not
depend on the batch it runs in (tests/test_batch_consistency.py), so batch size, workers and scheduler
never change a number.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import pyarrow as pa

from vrusim.engine.simulate import simulate
from vrusim.metrics.columns import result_columns
from vrusim.planners.registry import make_planner
from vrusim.scenario.schema import Scenario
from vrusim.sweep.columnar import ColumnarPacker
from vrusim.sweep.gc_pause import gc_paused
from vrusim.sweep.plan import SweepPlan, VariantBuilder
from vrusim.sweep.tables import chunk_table


@dataclass(frozen=True)
class ChunkTask:
    """Batch `index` of a plan: its design rows (arrays by column) and the numba threads to use."""

    plan: SweepPlan
    plan_digest: str
    index: int
    rows: dict[str, np.ndarray]
    """The batch's design rows, by column."""
    types: dict[str, pa.DataType]
    """Arrow type of each design column (`vrusim.sweep.tables.design_types`)."""
    threads: int = 0
    """Numba threads for the kernels; 0 leaves the process's setting alone."""


_BUILDERS: dict[str, tuple[VariantBuilder, ColumnarPacker | None]] = {}
"""Per process: the variant builder and columnar packer of each plan seen (bases validated once, not once per
batch)."""


def _builders(task: ChunkTask) -> tuple[VariantBuilder, ColumnarPacker | None]:
    found = _BUILDERS.get(task.plan_digest)
    if found is None:
        _BUILDERS.clear()
        builder = VariantBuilder(task.plan)
        found = _BUILDERS[task.plan_digest] = (builder, ColumnarPacker.of(task.plan, builder.bases))
    return found


def _merged(runs: list[tuple[np.ndarray, dict[str, np.ndarray]]], count: int) -> dict[str, np.ndarray]:
    """Result columns of sub-batches (their rows, their columns) merged in variant order."""
    if len(runs) == 1:
        return runs[0][1]
    merged: dict[str, np.ndarray] = {}
    for rows, columns in runs:
        for name, values in columns.items():
            if name not in merged:
                floats = values.dtype.kind == "f"
                merged[name] = np.full(count, np.nan if floats else None, dtype=float if floats else object)
            merged[name][rows] = values
    return merged


def _simulate_groups(scenarios: list[Scenario]) -> dict[str, np.ndarray]:
    """Result columns of the scenarios in order, running one batch per (planner, dt) group."""
    groups: dict[tuple[str, float], list[int]] = {}
    for row, scenario in enumerate(scenarios):
        groups.setdefault((scenario.planner.name, scenario.sim.dt_s), []).append(row)
    runs = [
        (np.array(rows), result_columns(simulate([scenarios[r] for r in rows], planner=make_planner(planner))))
        for (planner, _), rows in groups.items()
    ]
    return _merged(runs, len(scenarios))


def _lists(rows: dict[str, np.ndarray], select: Sequence[int] | np.ndarray) -> dict[str, list[Any]]:
    """Design rows `select` as Python values (what a `Scenario` is validated from)."""
    return {name: np.asarray(column)[select].tolist() for name, column in rows.items()}


def batch_columns(task: ChunkTask) -> dict[str, np.ndarray]:
    """The result columns of a batch's variants: packed from the design columns when every swept field has a
    writer (a flagged variant is built as a `Scenario` first, to raise its own message), else from one
    validated `Scenario` per variant."""
    builder, packer = _builders(task)
    count = len(task.rows["variant"])
    flagged = None if packer is None else packer.flagged(task.rows)
    if packer is None or flagged is None:
        return _simulate_groups(builder.build(_lists(task.rows, np.arange(count)), range(count)))
    if flagged.size:
        builder.build(_lists(task.rows, flagged), range(flagged.size))  # raises the first bad variant's message
    runs = [
        (rows, result_columns(simulate(params, planner=make_planner(planner))))
        for rows, planner, params in packer.groups(task.rows)
    ]
    return _merged(runs, count)


def run_chunk(task: ChunkTask) -> pa.Table:
    """Simulate one batch; the table has the design columns, then the result columns."""
    if task.threads > 0:
        import numba

        numba.set_num_threads(min(task.threads, numba.config.NUMBA_NUM_THREADS))
    with gc_paused():
        columns = batch_columns(task)
    return chunk_table(task.rows, task.types, columns)
