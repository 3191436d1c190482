"""An OpenSCENARIO parameter distribution file as one sweep: each parameter set is a variant.

Each variant is the distribution's scenario file imported with that parameter set replacing its declared
values (`vrusim.formats.xosc_import.read_xosc`), so a parameter may change anything the file computes from it.
The plan has one base per variant (keyed `<stem>#<index>` in the `test` column) and no swept field paths; the
parameter values become the design columns `param.<name>` (numbers when every value is one, else text), so
they appear in every results row. Variants run in batches of `DEFAULT_BATCH_SIZE` unless told otherwise.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from vrusim.errors import UserInputError
from vrusim.formats.xosc_distribution import ParameterSets, is_distribution, iter_sets, read_distribution
from vrusim.formats.xosc_import import parse_root, read_xosc_root
from vrusim.scenario.schema import Scenario
from vrusim.sweep.plan import PlannedSweep, SweepPlan, check_budgets

PARAMETER_PREFIX = "param."
"""Results column of OpenSCENARIO parameter NAME: `param.NAME`."""
DEFAULT_BATCH_SIZE = 2000
DEFAULT_SEED = 0
"""Master seed of the variants' `sim.seed` (sensor and V2X noise) unless --seed gives one."""


def _typed(values: list[str]) -> tuple[Any, ...]:
    """The values as numbers when every one reads as a finite number, else as the text."""
    try:
        numbers = [float(v) for v in values]
    except ValueError:
        return tuple(values)
    return tuple(numbers) if all(abs(n) < float("inf") for n in numbers) else tuple(values)


def variants(sets: ParameterSets) -> list[Scenario]:
    """The scenario of each parameter set (the scenario file's XML read once; runs draw no road, so the bases
    carry no drawn road lines)."""
    root, path = read_xosc_root(sets.scenario_file)
    return [parse_root(root, path, values, drawing=False) for values in iter_sets(sets)]


def distribution_sweep(path: str | Path, seed: int | None = None, batch_size: int | None = None) -> PlannedSweep:
    """The sweep of the distribution file `path`: its variants built and checked, nothing run."""
    root, path = read_xosc_root(path)
    if not is_distribution(root):
        raise UserInputError(
            f"{path}: is an OpenSCENARIO scenario, not a parameter distribution (<ParameterValueDistribution>): "
            f"run it with `vrusim run {path}`; `vrusim sweep` takes a sweep spec or a distribution file"
        )
    sets = read_distribution(root, path)
    scenarios = variants(sets)
    width = len(str(len(scenarios) - 1))
    keys = [f"{sets.scenario_file.stem}#{i:0{width}d}" for i in range(len(scenarios))]
    columns = tuple(
        (PARAMETER_PREFIX + name, _typed([row[i] for row in sets.rows])) for i, name in enumerate(sets.names)
    )
    plan = SweepPlan(
        name=path.stem,
        bases={key: s.model_dump(mode="json") for key, s in zip(keys, scenarios, strict=True)},
        parameters=(),
        samples=1,
        seed=DEFAULT_SEED if seed is None else seed,
        batch_size=batch_size or DEFAULT_BATCH_SIZE,
        base_columns=columns,
    )
    check_budgets(plan, scenarios)
    described = tuple(
        {"name": name, "kind": "openscenario", "distribution": sets.kind, "values": len(set(values))}
        for name, values in columns
    )
    source = {"distribution": str(path), "scenario": str(sets.scenario_file), "kind": sets.kind}
    return PlannedSweep(plan, source, sets.scenario_file, described)
