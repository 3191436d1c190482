"""One batch of a sweep, as run by a worker: build its variants, simulate them, return one table row each.

Variants of one batch that use different planners or time steps run as separate sub-batches (one engine
batch runs one planner at one dt); rows come back in variant order either way. A variant's results do not
depend on the batch it runs in (tests/test_batch_consistency.py), so batch size, workers and scheduler
never change a number.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import pyarrow as pa

from vrusim.engine.simulate import simulate
from vrusim.metrics.columns import result_columns
from vrusim.planners.registry import make_planner
from vrusim.scenario.schema import Scenario
from vrusim.sweep.gc_pause import gc_paused
from vrusim.sweep.plan import SweepPlan, VariantBuilder
from vrusim.sweep.tables import chunk_table


@dataclass(frozen=True)
class ChunkTask:
    """Batch `index` of a plan: its design rows (Python lists by column) and the numba threads to use."""

    plan: SweepPlan
    plan_digest: str
    index: int
    rows: dict[str, list[Any]]
    types: dict[str, pa.DataType]
    """Arrow type of each design column (`vrusim.sweep.tables.design_types`)."""
    threads: int = 0
    """Numba threads for the kernels; 0 leaves the process's setting alone."""


_BUILDERS: dict[str, VariantBuilder] = {}
"""Per process: the variant builder of each plan seen (bases validated once, not once per batch)."""


def _builder(task: ChunkTask) -> VariantBuilder:
    builder = _BUILDERS.get(task.plan_digest)
    if builder is None:
        _BUILDERS.clear()
        builder = _BUILDERS[task.plan_digest] = VariantBuilder(task.plan)
    return builder


def _simulate_groups(scenarios: list[Scenario]) -> dict[str, np.ndarray]:
    """Result columns of the scenarios in order, running one batch per (planner, dt) group."""
    groups: dict[tuple[str, float], list[int]] = {}
    for row, scenario in enumerate(scenarios):
        groups.setdefault((scenario.planner.name, scenario.sim.dt_s), []).append(row)
    if len(groups) == 1:
        ((planner, _),) = groups
        return result_columns(simulate(scenarios, planner=make_planner(planner)))
    merged: dict[str, np.ndarray] = {}
    for (planner, _), rows in groups.items():
        columns = result_columns(simulate([scenarios[r] for r in rows], planner=make_planner(planner)))
        for name, values in columns.items():
            if name not in merged:
                floats = values.dtype.kind == "f"
                merged[name] = np.full(len(scenarios), np.nan if floats else None, dtype=float if floats else object)
            merged[name][rows] = values
    return merged


def run_chunk(task: ChunkTask) -> pa.Table:
    """Simulate one batch; the table has the design columns, then the result columns."""
    if task.threads > 0:
        import numba

        numba.set_num_threads(min(task.threads, numba.config.NUMBA_NUM_THREADS))
    rows = range(len(task.rows["variant"]))
    with gc_paused():
        scenarios = _builder(task).build(task.rows, rows)
        columns = _simulate_groups(scenarios)
    return chunk_table(task.rows, task.types, columns)
