"""Batches of a sweep packed straight from its design columns, without a `Scenario` per variant.

The bases of a batch (one for a scenario file, the catalogue tests its variants use otherwise) are packed
once, in order of first use, and copied to every variant (`vrusim.sim.compaction.take`): the same arrays
`pack` gives for the variants themselves, path tables included. Each swept field's writer
(`vrusim.sweep.field_columns`) then writes its column. A variant whose values a column check flags is built as
a `Scenario` (its error is then exactly the per-variant message); a sweep with a field that has no writer
builds every variant that way.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from vrusim.scenario.field_paths import Step, parse_path
from vrusim.scenario.schema import Scenario
from vrusim.scenario.v2x import resolve_channel
from vrusim.sim.compaction import take
from vrusim.sim.params import BatchParams, pack
from vrusim.sweep.field_columns import FieldRule, FieldWriter, field_rule, writer_for
from vrusim.sweep.plan import FILE_BASE, TEST_COLUMN, SweepPlan


def base_value(base: Scenario, steps: tuple[Step, ...]) -> Any:
    """The value of the field at `steps` in `base` (a channel profile name read as its specification)."""
    node: Any = base
    for step in steps:
        node = node[step] if isinstance(step, int) else getattr(node, step)
        if step == "channel" and isinstance(node, str):
            node = resolve_channel(node)
    return node


def _array(values: list[Any]) -> np.ndarray:
    """Base values as floats (None: NaN) when they are numbers, else as objects."""
    if all(v is None or (isinstance(v, int | float) and not isinstance(v, bool)) for v in values):
        return np.array([math.nan if v is None else v for v in values], dtype=float)
    array = np.empty(len(values), dtype=object)
    array[:] = values
    return array


@dataclass(frozen=True)
class _Field:
    path: str
    writer: FieldWriter
    index: tuple[int, ...]
    rule: FieldRule | None


class _Values:
    """A `Getter` over some rows of a batch: swept columns, or each row's base value."""

    def __init__(self, columns: Mapping[str, np.ndarray], bases: Sequence[Scenario], base_index: np.ndarray) -> None:
        self.columns, self.bases, self.base_index = columns, bases, base_index
        self.cache: dict[str, np.ndarray] = {}

    def __call__(self, path: str) -> np.ndarray:
        if path in self.columns:
            return self.columns[path]
        if path not in self.cache:
            steps = parse_path(path)
            self.cache[path] = _array([base_value(base, steps) for base in self.bases])[self.base_index]
        return self.cache[path]


class ColumnarPacker:
    """Packs the batches of a plan from design columns, when every swept field has a writer for every base."""

    def __init__(self, plan: SweepPlan, bases: Mapping[str, Scenario], fields: list[_Field]) -> None:
        self.plan, self.bases, self.fields = plan, bases, fields

    @classmethod
    def of(cls, plan: SweepPlan, bases: Mapping[str, Scenario]) -> ColumnarPacker | None:
        """The packer of `plan` (its bases validated), or None when some swept field has no applicable writer."""
        first = next(iter(bases.values()))
        fields = []
        for parameter in plan.parameters:
            found = writer_for(parameter.path, list(bases.values()))
            if found is None:
                return None
            writer, index = found
            fields.append(_Field(parameter.path, writer, index, field_rule(first, parse_path(parameter.path))))
        if any(field_rule(base, parse_path(f.path)) != f.rule for base in bases.values() for f in fields):
            return None  # a field declared differently on another base (never for built-in models)
        return cls(plan, bases, fields)

    def _bases_of(self, rows: Mapping[str, np.ndarray], select: np.ndarray) -> tuple[list[Scenario], np.ndarray]:
        """The distinct bases of the rows `select`, in order of first use, and each row's index into them."""
        tests = rows.get(TEST_COLUMN)
        if tests is None:  # one scenario file: every row its base
            return [self.bases[FILE_BASE]], np.zeros(select.size, dtype=np.int64)
        keys = tests[select].tolist()
        order: dict[str, int] = {}
        index = np.array([order.setdefault(key, len(order)) for key in keys], dtype=np.int64)
        return [self.bases[key] for key in order], index

    def flagged(self, rows: Mapping[str, np.ndarray]) -> np.ndarray | None:
        """Rows whose values a column check does not pass (in order), or None when a column's type is not its
        field's (every row then needs building)."""
        count = rows["variant"].size
        bases, base_index = self._bases_of(rows, np.arange(count))
        values = _Values({f.path: rows[f.path] for f in self.fields}, bases, base_index)
        ok = np.ones(count, dtype=bool)
        for f in self.fields:
            if f.rule is None:
                return None
            keeps = f.rule.keeps(rows[f.path])
            if keeps is None:
                return None
            ok &= keeps
        for f in self.fields:
            if f.writer.rule is not None:
                with np.errstate(invalid="ignore", over="ignore"):
                    ok &= f.writer.rule(values, f.index)
        return np.flatnonzero(~ok)

    def groups(self, rows: Mapping[str, np.ndarray]) -> list[tuple[np.ndarray, str, BatchParams]]:
        """The batch's variants as (rows, planner name, packed batch), one per (planner, dt) of their bases,
        in order of first use (the rows must pass `flagged`)."""
        count = rows["variant"].size
        bases, base_index = self._bases_of(rows, np.arange(count))
        keys = [(base.planner.name, base.sim.dt_s) for base in bases]
        order: dict[tuple[str, float], int] = {}
        group_of = np.array([order.setdefault(key, len(order)) for key in keys], dtype=np.int64)[base_index]
        out = []
        for position, (planner, _) in enumerate(order):
            select = np.flatnonzero(group_of == position)
            out.append((select, planner, self._pack(rows, select)))
        return out

    def _pack(self, rows: Mapping[str, np.ndarray], select: np.ndarray) -> BatchParams:
        bases, base_index = self._bases_of(rows, select)
        params = take(pack(bases), base_index)
        values = _Values({f.path: rows[f.path][select] for f in self.fields}, bases, base_index)
        params.seed[:] = rows["seed"][select]
        for f in self.fields:
            f.writer.effect(params, values, f.path, f.index)
        return replace(params, n_steps=math.ceil(params.duration_s.max() / params.dt_s - 1e-9))
