"""The design of a sweep: every variant's id, seed, test and parameter values, fixed before anything runs.

Variant i sits at grid point g = i // samples and sample s = i % samples; grid dimensions (catalogue tests
first, then grid parameters in spec order) vary slowest-first. Each random parameter draws its N values
from its own generator, PCG64 seeded by (master seed, CRC-32 of its path), so adding or removing another
parameter never changes its draws. Parameters named in `correlation` are instead drawn together through a
Gaussian copula: standard normals with the given correlation matrix (one generator keyed by their paths),
mapped through the normal CDF to uniforms and through each parameter's inverse CDF to its own distribution;
each keeps its marginal distribution exactly. Each variant's `sim.seed` (the key of its sensor and V2X random
numbers) is SplitMix64 of (master seed, variant id). The design depends on the plan only, never on batch size,
workers or scheduler.
"""

from __future__ import annotations

import math
import zlib
from typing import Any

import numpy as np

from vrusim.sweep.normal import normal_cdf, normal_quantile
from vrusim.sweep.plan import TEST_COLUMN, SweepPlan
from vrusim.sweep.spec import Parameter, correlation_matrix
from vrusim.sweep.truncated import truncated_normal

_GOLDEN, _MIX1, _MIX2 = np.uint64(0x9E3779B97F4A7C15), np.uint64(0xBF58476D1CE4E5B9), np.uint64(0x94D049BB133111EB)


def _splitmix(z: np.ndarray) -> np.ndarray:
    with np.errstate(over="ignore"):
        z = (z ^ (z >> np.uint64(30))) * _MIX1
        z = (z ^ (z >> np.uint64(27))) * _MIX2
    return z ^ (z >> np.uint64(31))


def variant_seeds(master_seed: int, count: int) -> np.ndarray:
    """Each variant's `sim.seed` in [0, 2^63): SplitMix64 of (master seed, variant id)."""
    ids = np.arange(count, dtype=np.uint64)
    with np.errstate(over="ignore"):
        z = _splitmix(np.uint64(master_seed) * _GOLDEN + np.uint64(0x5EED)) + ids * _GOLDEN
    return (_splitmix(z) >> np.uint64(1)).astype(np.int64)


def _generator(seed: int, path: str) -> np.random.Generator:
    return np.random.Generator(np.random.PCG64(np.random.SeedSequence([seed, zlib.crc32(path.encode())])))


def _column(values: list[Any]) -> np.ndarray:
    """Values as a typed array when they are all numbers or all booleans, else an object array."""
    if all(isinstance(v, bool) for v in values):
        return np.array(values, dtype=bool)
    if all(isinstance(v, int) and not isinstance(v, bool) for v in values) and all(abs(v) < 2**63 for v in values):
        return np.array(values, dtype=np.int64)
    if all(isinstance(v, int | float) and not isinstance(v, bool) for v in values):
        return np.array(values, dtype=float)
    array = np.empty(len(values), dtype=object)
    array[:] = values
    return array


def _draw(p: Parameter, seed: int, count: int) -> np.ndarray:
    rng = _generator(seed, p.path)
    if p.kind == "uniform":
        return rng.uniform(p.low, p.high, count)
    if p.kind == "normal":
        return rng.normal(p.mean, p.std, count)
    if p.kind == "truncated_normal":
        return truncated_normal(rng, p, count)
    index = rng.choice(len(p.values), size=count, p=list(p.weights) if p.weights else None)
    return _column(list(p.values))[index]


def _from_normal(p: Parameter, z: np.ndarray) -> np.ndarray:
    """Standard normal draws `z` mapped onto the distribution of `p` (its inverse CDF at Φ(z))."""
    if p.kind == "normal":
        return p.mean + p.std * z
    u = normal_cdf(z)
    if p.kind == "uniform":
        return np.minimum(p.low + u * (p.high - p.low), np.nextafter(p.high, p.low))  # U[low, high)
    if p.kind == "truncated_normal":
        lo, hi = normal_cdf((p.low - p.mean) / p.std), normal_cdf((p.high - p.mean) / p.std)
        return np.clip(p.mean + p.std * normal_quantile(lo + u * (hi - lo)), p.low, p.high)
    weights = np.asarray(p.weights) if p.weights else np.full(len(p.values), 1.0 / len(p.values))
    index = np.minimum(np.searchsorted(np.cumsum(weights), u, side="right"), len(p.values) - 1)
    return _column(list(p.values))[index]


def _correlated_draws(plan: SweepPlan, count: int) -> dict[str, np.ndarray]:
    """The columns of the correlated parameters, drawn jointly (Gaussian copula)."""
    paths, matrix = correlation_matrix(plan.correlations, plan.parameters)
    normals = _generator(plan.seed, "correlation:" + "|".join(paths)).standard_normal((count, len(paths)))
    joint = normals @ np.linalg.cholesky(matrix).T
    by_path = {p.path: p for p in plan.parameters}
    return {path: _from_normal(by_path[path], joint[:, i]) for i, path in enumerate(paths)}


def make_design(plan: SweepPlan) -> dict[str, np.ndarray]:
    """Columns `variant`, `seed`, optional `test`, the plan's base columns and one per parameter (named by its
    path), N rows each."""
    count = plan.variants
    dimensions: list[tuple[str, np.ndarray]] = []
    if plan.tests:
        dimensions.append((TEST_COLUMN, _column(list(plan.tests))))
    dimensions += [(p.path, _column(list(p.values))) for p in plan.parameters if not p.is_random]
    sizes = [len(values) for _, values in dimensions]
    grid_index = np.arange(count, dtype=np.int64) // plan.samples
    columns: dict[str, np.ndarray] = {
        "variant": np.arange(count, dtype=np.int64),
        "seed": variant_seeds(plan.seed, count),
    }
    for position, (name, values) in enumerate(dimensions):
        stride = math.prod(sizes[position + 1 :])
        columns[name] = values[(grid_index // stride) % sizes[position]]
    if plan.base_columns:
        stride = math.prod(sizes[1:])
        base_index = (grid_index // stride) % sizes[0]
        for name, values in plan.base_columns:
            columns[name] = _column(list(values))[base_index]
    correlated = _correlated_draws(plan, count) if plan.correlations else {}
    for p in plan.parameters:
        if p.is_random:
            columns[p.path] = correlated[p.path] if p.path in correlated else _draw(p, plan.seed, count)
    if "sim.seed" in columns:
        with np.errstate(invalid="ignore"):  # a seed beyond int64 is refused when its variant is built
            columns["seed"] = columns["sim.seed"].astype(np.int64)
    return columns


def design_rows(design: dict[str, np.ndarray], start: int, stop: int) -> dict[str, np.ndarray]:
    """Rows [start, stop) of a design (copies: a batch pickles only its own rows)."""
    return {name: column[start:stop].copy() for name, column in design.items()}


def _first_of_each(column: np.ndarray, limit: int) -> list[int]:
    """The row of the first occurrence of each distinct value (at most `limit` of them)."""
    if column.dtype.kind in "fib":  # (0.0 and -0.0 count as one value here, as two below: both check alike)
        return np.unique(column, return_index=True)[1][:limit].tolist()
    seen: dict[str, int] = {}
    for row, value in enumerate(column.tolist()):
        key = repr(value)
        if key not in seen:
            seen[key] = row
            if len(seen) >= limit:
                break
    return list(seen.values())


def preflight_rows(
    design: dict[str, np.ndarray], plan: SweepPlan, first: int = 256, max_distinct: int | None = None
) -> list[int]:
    """Rows worth validating before a sweep starts: the first `first`, each parameter's extremes and every
    distinct value of a discrete parameter (first occurrence; only for parameters with at most `max_distinct`
    values when given), and the last row."""
    rows = set(range(min(first, plan.variants)))
    rows.add(plan.variants - 1)
    for p in plan.parameters:
        column = design[p.path]
        if column.dtype.kind in "fi":
            rows.update((int(np.argmin(column)), int(np.argmax(column))))
        if (not p.is_random or p.kind == "choice") and (max_distinct is None or len(p.values) <= max_distinct):
            rows.update(_first_of_each(column, len(p.values)))
    if TEST_COLUMN in design:
        first_of_test: dict[str, int] = {}
        for row in range(0, plan.variants, plan.samples):
            first_of_test.setdefault(design[TEST_COLUMN][row], row)
        rows.update(first_of_test.values())
    return sorted(rows)
