"""A sweep plan: the spec resolved into base scenarios, checked paths and counts; variants built from it.

The plan holds everything a variant depends on and nothing else (no file paths), so it travels to worker
processes or a Dask cluster as it is, and its digest identifies the results of a sweep for `--resume`.
"""

from __future__ import annotations

import hashlib
import json
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from vrusim.errors import UserInputError
from vrusim.limits import check_limit
from vrusim.scenario.loading import load_scenario, scenario_from_mapping
from vrusim.scenario.schema import Scenario
from vrusim.sweep.field_paths import Step, check_path, with_values
from vrusim.sweep.spec import Correlation, Parameter, SweepSpec, check_batch_size

TEST_COLUMN = "test"
"""Design column of a catalogue sweep: the Euro NCAP test id of each variant."""
FILE_BASE = ""
"""Key of the single base of a sweep over a scenario file."""


@dataclass(frozen=True)
class SweepPlan:
    """What the variants of a sweep are made of (picklable, JSON-describable)."""

    name: str
    bases: dict[str, dict[str, Any]]
    """Base scenario data (overrides applied) by test id; one entry `FILE_BASE` for a file base."""
    parameters: tuple[Parameter, ...]
    samples: int
    seed: int
    batch_size: int
    correlations: tuple[Correlation, ...] = ()
    """Correlated pairs of random parameters (Gaussian copula); empty: all draws independent."""
    base_columns: tuple[tuple[str, tuple[Any, ...]], ...] = ()
    """Extra design columns set by the base: (column, one value per base in `bases` order), e.g. the
    OpenSCENARIO parameter values of each variant of a parameter distribution (`param.NAME`)."""

    @property
    def tests(self) -> tuple[str, ...]:
        """The catalogue tests (the first grid dimension), or () for a file base."""
        return () if FILE_BASE in self.bases else tuple(self.bases)

    @property
    def grid_points(self) -> int:
        """Number of grid combinations (tests × grid parameter values)."""
        return max(1, len(self.tests)) * math.prod(len(p.values) for p in self.parameters if not p.is_random)

    @property
    def variants(self) -> int:
        """Total number of variants: grid points × samples."""
        return self.grid_points * self.samples

    @property
    def chunks(self) -> int:
        """Number of batches (= results files)."""
        return math.ceil(self.variants / self.batch_size)

    def chunk_range(self, index: int) -> tuple[int, int]:
        """First and one-past-last variant of batch `index`."""
        start = index * self.batch_size
        return start, min(self.variants, start + self.batch_size)

    def describe(self) -> dict[str, Any]:
        """JSON-ready description (the manifest's `plan`); `correlations` only when there are any, so that the
        digests of sweeps without them stay what they were."""
        out = {
            "name": self.name,
            "bases": self.bases,
            "parameters": [p.describe() for p in self.parameters],
            "samples": self.samples,
            "seed": self.seed,
            "batch_size": self.batch_size,
        }
        if self.correlations:
            out["correlations"] = [list(pair) for pair in self.correlations]
        if self.base_columns:
            out["base_columns"] = [[name, list(values)] for name, values in self.base_columns]
        return out

    def digest(self) -> str:
        """SHA-256 of the description: equal digests mean equal variants in equal batches."""
        text = json.dumps(self.describe(), sort_keys=True, separators=(",", ":"), allow_nan=False)
        return hashlib.sha256(text.encode()).hexdigest()


@dataclass(frozen=True)
class PlannedSweep:
    """A sweep planned outside the spec format (an OpenSCENARIO parameter distribution: one base per variant),
    with what the manifest records of it."""

    plan: SweepPlan
    source: dict[str, Any]
    """What the manifest records as the spec."""
    base_file: Path | None
    columns: tuple[dict[str, Any], ...] = ()
    """Descriptions of the plan's base columns (the manifest's `parameters`)."""


def _dump(scenario: Scenario) -> dict[str, Any]:
    return scenario.model_dump(mode="json")


def _apply_overrides(base: Scenario, overrides: dict[str, Any]) -> Scenario:
    assignments = [(check_path(base, path, "set"), value) for path, value in overrides.items()]
    return with_values(base, assignments, f"{base.name} with `set`") if assignments else base


def _catalogue_bases(spec: SweepSpec) -> dict[str, Scenario]:
    from vrusim.ncap.build import build_test
    from vrusim.ncap.grid import select
    from vrusim.planners.registry import make_planner

    choice = spec.catalogue
    assert choice is not None
    try:
        make_planner(choice.planner)
    except UserInputError as error:
        raise UserInputError(str(error).replace("planner.name:", "catalogue.planner:", 1)) from None
    try:
        tests = select(choice.scenarios, choice.night, choice.protocol)
    except UserInputError as error:
        message = str(error).replace("--scenario:", "catalogue.scenarios:", 1)
        raise UserInputError(message.replace("--protocol:", "catalogue.protocol:", 1)) from None
    return {test.test_id: build_test(test, choice.planner, choice.v2x).scenario for test in tests}


def make_plan(spec: SweepSpec, batch_size: int | None = None) -> SweepPlan:
    """Resolve the spec: load or build the bases, apply `set`, check every parameter path on every base."""
    bases = {FILE_BASE: load_scenario(spec.base_file)} if spec.base_file is not None else _catalogue_bases(spec)
    resolved = {key: _apply_overrides(base, spec.overrides) for key, base in bases.items()}
    for base in resolved.values():
        for parameter in spec.parameters:
            check_path(base, parameter.path)
    check_batch_size(batch_size)
    plan = SweepPlan(
        name=spec.name,
        bases={key: _dump(base) for key, base in resolved.items()},
        parameters=spec.parameters,
        samples=spec.samples,
        seed=spec.seed,
        batch_size=batch_size or spec.batch_size,
        correlations=spec.correlations,
    )
    check_budgets(plan, resolved.values())
    return plan


def check_budgets(plan: SweepPlan, bases: Iterable[Scenario]) -> None:
    """Refuse a plan beyond the work budgets before its design is drawn: its variants (catalogue tests
    included) and the variant-steps of one batch (at the bases' step counts; a swept duration is checked again
    per batch by the engine)."""
    check_limit("sweep_variants", plan.variants, f"{plan.name}: samples x {plan.grid_points:,} grid points")
    steps = max(math.ceil(base.sim.duration_s / base.sim.dt_s - 1e-9) for base in bases)
    batch = min(plan.batch_size, plan.variants)
    check_limit("batch_variant_steps", batch * steps, f"batch_size: {batch:,} variants x {steps:,} steps")


class VariantBuilder:
    """Builds the variants of a plan from design rows (bases validated once per process)."""

    def __init__(self, plan: SweepPlan) -> None:
        self.plan = plan
        self.bases = {key: scenario_from_mapping(data, key or plan.name) for key, data in plan.bases.items()}
        first = next(iter(self.bases.values()))
        self.steps: list[tuple[Step, ...]] = [check_path(first, p.path) for p in plan.parameters]

    def label(self, design: dict[str, Sequence[Any]], row: int) -> str:
        """A variant as messages name it: `variant 1 (planner.name='aeb')`."""
        values = ", ".join(f"{p.path}={design[p.path][row]!r}" for p in self.plan.parameters)
        return f"variant {design['variant'][row]} ({values})"

    def build(self, design: dict[str, Sequence[Any]], rows: range | Sequence[int]) -> list[Scenario]:
        """The variants at the given design rows; a bad variant raises UserInputError naming it and the field."""
        names = [p.path for p in self.plan.parameters]
        columns = [design[name] for name in names]
        tests = design.get(TEST_COLUMN)
        seeds = design["seed"]
        out = []
        for row in rows:
            base = self.bases[tests[row] if tests is not None else FILE_BASE]
            values = [column[row] for column in columns]
            try:
                scenario = with_values(base, list(zip(self.steps, values, strict=True)), "")
            except UserInputError as error:
                raise UserInputError(f"{self.label(design, row)}{error}") from None
            if "sim.seed" not in names:
                scenario = scenario.model_copy(
                    update={"sim": scenario.sim.model_copy(update={"seed": int(seeds[row])})}
                )
            out.append(scenario)
        return out
