"""Checking a sweep's variants before it starts (and before `--dry-run` reports), in bounded memory and time.

When every swept field has a column writer (`vrusim.sweep.columnar`), a batch is run from its design columns
after one column check per field, and only the variants that check flags are built as `Scenario`s. That
check is then the whole per-variant validation, so the preflight runs it over the whole design (in slices of
`SLICE` rows) and builds a flagged variant to raise its message. It then builds and packs a sample: the first
batch's rows, each parameter's extremes, the last row, and every distinct value of a discrete parameter with
at most `MAX_DISTINCT` of them (a grid of a million values is covered by the column check instead of a million
`Scenario`s). Without column writers every distinct value is built, `SLICE` rows at a time.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vrusim.engine.compiled_run import compiled_support
from vrusim.errors import UserInputError
from vrusim.planners.registry import make_planner
from vrusim.scenario.schema import Scenario
from vrusim.sim.params import pack
from vrusim.sweep.columnar import ColumnarPacker
from vrusim.sweep.design import design_rows, preflight_rows
from vrusim.sweep.plan import SweepPlan, VariantBuilder

SLICE = 2_000
"""Rows checked or built at a time."""
MAX_DISTINCT = 1_000
"""Discrete parameters with more distinct values than this are sampled when the column check covers them."""


@dataclass(frozen=True)
class Preflight:
    """What checking a sweep's variants found."""

    checked: int
    """Variants built and checked."""
    compiled: bool
    """Every sampled variant runs the engine's compiled step (`engine.compiled_run`), which spreads a batch over
    the cores as threads of one process."""
    column_checked: bool = False
    """Every variant passed the column checks its batch will run (`vrusim.sweep.columnar`)."""


def _column_check(plan: SweepPlan, builder: VariantBuilder, design: dict[str, np.ndarray]) -> bool:
    """Run the batches' column check over every row (a flagged row is built: its error is raised); False when
    the sweep's batches build every variant instead."""
    packer = ColumnarPacker.of(plan, builder.bases)
    if packer is None:
        return False
    for start in range(0, plan.variants, SLICE * 50):
        rows = design_rows(design, start, min(plan.variants, start + SLICE * 50))
        flagged = packer.flagged(rows)
        if flagged is None:
            return False
        for first in range(0, flagged.size, SLICE):
            some = flagged[first : first + SLICE]
            builder.build({k: v[some].tolist() for k, v in rows.items()}, range(some.size))
    return True


def _raise_for_first(
    builder: VariantBuilder, rows: dict[str, list], variants: list[tuple[int, Scenario]], planner: str
) -> None:
    """Raise the planner's error for the first of `variants` (position in `rows`, scenario) it refuses, naming
    the variant and its parameter values."""
    for position, scenario in variants:
        try:
            make_planner(planner).reset(pack([scenario]))
        except UserInputError as error:
            raise UserInputError(f"{builder.label(rows, position)}: {error}") from None


def preflight(plan: SweepPlan, design: dict[str, np.ndarray]) -> Preflight:
    """Check the variants of a sweep (see the module); a bad one raises UserInputError naming it."""
    builder = VariantBuilder(plan)
    column_checked = _column_check(plan, builder, design)
    rows = preflight_rows(design, plan, max_distinct=MAX_DISTINCT if column_checked else None)
    compiled = True
    for first in range(0, len(rows), SLICE):
        some = rows[first : first + SLICE]
        rows_of = {k: v[some].tolist() for k, v in design.items()}
        scenarios = builder.build(rows_of, range(len(some)))
        by_planner: dict[str, list[int]] = {}
        for position, scenario in enumerate(scenarios):
            by_planner.setdefault(scenario.planner.name, []).append(position)
        for name, positions in by_planner.items():
            batch, planner = pack([scenarios[i] for i in positions]), make_planner(name)
            try:
                planner.reset(batch)  # planner.params validated by the planner
            except UserInputError:
                _raise_for_first(builder, rows_of, [(i, scenarios[i]) for i in positions], name)
                raise  # pragma: no cover (the batch failed, so one of its variants does)
            compiled = compiled and compiled_support(batch, planner, None, trace=False) is None
    return Preflight(len(rows), compiled, column_checked)
