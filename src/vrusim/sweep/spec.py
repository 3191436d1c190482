"""The sweep specification (YAML): a base, fixed overrides, swept parameters, samples and a master seed.

```yaml
name: pedestrian-monte-carlo
base: ../scenarios/paper/pedestrian_crossing.yaml      # or  catalogue: {scenarios: [CPNA], night: false}
set: {v2x.enabled: true}                              # fixed overrides, applied to every variant first
parameters:                                           # dotted field paths (docs/sweeps.md)
  ego.cruise_speed_mps: {uniform: [10, 20]}           # random: uniform, normal, truncated_normal, choice
  v2x.channel.latency_s: [0.0, 0.1, 0.3]              # grid: a list, {range: [a, b, step]}, {linspace: [a, b, n]}
samples: 1000                                         # random draws per grid point
correlation:                                          # optional: correlated random parameters
  - {between: [ego.cruise_speed_mps, "vrus[0].top_speed_mps"], rho: 0.5}   # quote paths with [ ] in a flow list
seed: 7
batch_size: 2000                                      # variants per batch (= per results file)
```
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np
from pydantic import Field, ValidationError, model_validator

from vrusim.errors import UserInputError
from vrusim.io.paths import check_name
from vrusim.limits import check_limit
from vrusim.scenario.bounds import bound_excess
from vrusim.scenario.field_paths import describe_validation_error
from vrusim.scenario.strict import StrictModel
from vrusim.scenario.text import OneLineText, Text
from vrusim.scenario.yaml_file import read_yaml_file
from vrusim.sweep.field_paths import check_overlaps
from vrusim.sweep.normal import normal_cdf

MIN_TRUNCATED_MASS = 1e-6
"""Least probability a truncated normal's interval may hold (`vrusim.sweep.truncated` draws it exactly down to
that; below it a spec is more likely mistaken than meant)."""
MAX_BATCH_SIZE = 1_000_000
"""Most variants in one batch (`batch_size`, `--batch-size`)."""
GRID_KINDS = ("grid",)
RANDOM_KINDS = ("uniform", "normal", "truncated_normal", "choice")


class CatalogueBase(StrictModel):
    """A catalogue selection as the base: every selected Euro NCAP test is one value of the `test` dimension."""

    scenarios: list[str] = Field(min_length=1, description="scenario codes or prefixes, as `vrusim ncap --scenario`")
    protocol: str | None = Field(None, description="Euro NCAP edition, as `vrusim ncap --protocol`; None: the default")
    night: bool = False
    v2x: bool = False
    planner: str = "fsm"


class CorrelationEntry(StrictModel):
    """Two random parameters whose draws are correlated (Gaussian copula, see `vrusim.sweep.design`)."""

    between: tuple[str, str] = Field(strict=False, description="two paths under `parameters`")
    rho: float = Field(gt=-1, lt=1, description="correlation of the underlying standard normals")


class SpecFile(StrictModel):
    """The YAML document as written (parameters are parsed separately into `Parameter`s)."""

    name: OneLineText | None = Field(None, min_length=1)
    description: Text = ""
    base: str | None = Field(None, min_length=1, description="scenario YAML file, relative to the spec file")
    catalogue: CatalogueBase | None = None
    set: dict[str, Any] = Field(default_factory=dict)
    parameters: dict[str, Any] = Field(default_factory=dict)
    samples: int = Field(1, ge=1, description="random draws per grid point (limit sweep_variants)")
    seed: int = Field(0, ge=0, lt=2**63)
    batch_size: int = Field(2000, ge=1, le=MAX_BATCH_SIZE)
    correlation: list[CorrelationEntry] = Field(default_factory=list, max_length=100)

    @model_validator(mode="after")
    def _one_base(self) -> SpecFile:
        if (self.base is None) == (self.catalogue is None):
            raise ValueError("give exactly one of base (a scenario file) or catalogue (Euro NCAP tests)")
        return self


@dataclass(frozen=True)
class Parameter:
    """One swept field: a grid of values, or a distribution drawn once per variant."""

    path: str
    kind: str
    """"grid", or a distribution: "uniform", "normal", "truncated_normal", "choice"."""
    values: tuple[Any, ...] = ()
    """grid: the values; choice: the choices."""
    weights: tuple[float, ...] = ()
    """choice: probabilities (normalised), empty for equal weights."""
    low: float = -math.inf
    high: float = math.inf
    mean: float = 0.0
    std: float = 0.0

    @property
    def is_random(self) -> bool:
        """Drawn per variant (True) or a grid dimension (False)."""
        return self.kind in RANDOM_KINDS

    @classmethod
    def from_description(cls, data: dict[str, Any]) -> Parameter:
        """The parameter a `describe()` mapping stands for."""
        fields = {k: v for k, v in data.items() if k not in ("name", "values", "weights")}
        return cls(data["name"], values=tuple(data.get("values", ())), weights=tuple(data.get("weights", ())), **fields)

    def describe(self) -> dict[str, Any]:
        """JSON-ready description for the manifest."""
        out: dict[str, Any] = {"name": self.path, "kind": self.kind}
        if self.kind in ("grid", "choice"):
            out["values"] = list(self.values)
        if self.weights:
            out["weights"] = list(self.weights)
        if self.kind in ("uniform", "truncated_normal"):
            out.update(low=self.low, high=self.high)
        if self.kind in ("normal", "truncated_normal"):
            out.update(mean=self.mean, std=self.std)
        return out


Correlation = tuple[str, str, float]
"""Two random parameters (paths, in spec order) and the correlation of their Gaussian copula."""


@dataclass(frozen=True)
class SweepSpec:
    """A validated sweep specification; base file paths resolved."""

    name: str
    description: str
    base_file: Path | None
    catalogue: CatalogueBase | None
    overrides: dict[str, Any]
    parameters: tuple[Parameter, ...]
    samples: int
    seed: int
    batch_size: int
    source: dict[str, Any]
    """The document as written (recorded in the manifest)."""
    correlations: tuple[Correlation, ...] = ()


def _numbers(where: str, value: Any, count: int, what: str) -> list[float]:
    if (
        not isinstance(value, list | tuple)
        or len(value) != count
        or not all(isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v) for v in value)
    ):
        raise UserInputError(f"{where}: expected {what}")
    return [float(v) for v in value]


def _named(where: str, value: Any, names: tuple[str, ...]) -> list[Any]:
    """Arguments given as a list in `names` order or as a mapping with exactly those keys."""
    if isinstance(value, dict):
        if set(value) != set(names):
            raise UserInputError(f"{where}: expected the keys {', '.join(names)}")
        return [value[n] for n in names]
    return value


def _finite_span(where: str, low: float, high: float, what: str) -> None:
    """Refuse ends so far apart that their difference overflows (the values would be infinite or NaN)."""
    if not math.isfinite(high - low):
        raise UserInputError(f"{where}: expected {what} to be a finite number, got {low:g} and {high:g}")


def _grid_range(where: str, value: Any) -> tuple[float, ...]:
    start, stop, step = _numbers(where, _named(where, value, ("start", "stop", "step")), 3, "[start, stop, step]")
    if step <= 0 or stop < start:
        raise UserInputError(f"{where}: expected step > 0 and stop >= start")
    _finite_span(where, start, stop, "stop - start")
    span = (stop - start) / step
    if not math.isfinite(span):  # a step so small the count overflows
        check_limit("sweep_variants", 1e300, f"{where}: its values")
    count = math.floor(span + 1e-9) + 1
    check_limit("sweep_variants", count, f"{where}: its values")
    return tuple(round(start + i * step, 12) for i in range(count))


def _linspace(where: str, value: Any) -> tuple[float, ...]:
    start, stop, count = _named(where, value, ("start", "stop", "count"))
    start, stop = _numbers(where, [start, stop], 2, "[start, stop, count]")
    if not isinstance(count, int) or isinstance(count, bool) or count < 1:
        raise UserInputError(f"{where}: count must be a whole number ≥ 1")
    check_limit("sweep_variants", count, f"{where}: count")
    _finite_span(where, start, stop, "stop - start")
    if count == 1:
        return (start,)
    return tuple(start + (stop - start) * i / (count - 1) for i in range(count))


def _choice(where: str, value: Any) -> tuple[tuple[Any, ...], tuple[float, ...]]:
    if isinstance(value, dict):
        if not set(value) <= {"values", "weights"} or "values" not in value:
            raise UserInputError(f"{where}: expected {{values: [...], weights: [...]}} or a list of values")
        values, weights = value["values"], value.get("weights")
    else:
        values, weights = value, None
    if not isinstance(values, list) or not values:
        raise UserInputError(f"{where}: expected a non-empty list of values")
    if weights is None:
        return tuple(values), ()
    numbers = _numbers(f"{where}.weights", weights, len(values), f"{len(values)} weights, one per value")
    total = sum(numbers)
    if any(w < 0 for w in numbers) or total <= 0:
        raise UserInputError(f"{where}.weights: expected non-negative weights with a positive sum")
    if not math.isfinite(total):  # weights near the float maximum: scaled first (finite sums stay as they were)
        numbers = [w / max(numbers) for w in numbers]
        total = sum(numbers)
    return tuple(values), tuple(w / total for w in numbers)


def truncated_mass(mean: float, std: float, low: float, high: float) -> float:
    """The probability N(mean, std²) gives [low, high], computed in the lower tail (a window above the mean is
    mirrored), where Φ keeps its relative accuracy far from the mean."""
    a, b = (low - mean) / std, (high - mean) / std
    if a > 0:
        a, b = -b, -a
    return float(normal_cdf(b) - normal_cdf(a))


def parse_parameter(path: str, value: Any) -> Parameter:
    """One entry of `parameters` (path: grid list or {kind: arguments}); UserInputError names the entry."""
    where = f"parameters.{path}"
    if isinstance(value, list):
        if not value:
            raise UserInputError(f"{where}: expected at least one value")
        return Parameter(path, "grid", tuple(value))
    if not isinstance(value, dict) or len(value) != 1:
        raise UserInputError(
            f"{where}: expected a list of values or one of {{range, linspace, values, uniform, normal, "
            "truncated_normal, choice}; give a fixed value under `set` instead"
        )
    ((kind, args),) = value.items()
    where = f"{where}.{kind}"
    if kind == "values":
        return parse_parameter(path, args)
    if kind == "range":
        return Parameter(path, "grid", _grid_range(where, args))
    if kind == "linspace":
        return Parameter(path, "grid", _linspace(where, args))
    if kind == "uniform":
        low, high = _numbers(where, _named(where, args, ("low", "high")), 2, "[low, high]")
        if not low < high:
            raise UserInputError(f"{where}: expected low < high")
        _finite_span(where, low, high, "high - low")
        return Parameter(path, "uniform", low=low, high=high)
    if kind == "normal":
        mean, std = _numbers(where, _named(where, args, ("mean", "std")), 2, "[mean, std]")
        if std <= 0:
            raise UserInputError(f"{where}: expected std > 0")
        return Parameter(path, "normal", mean=mean, std=std)
    if kind == "truncated_normal":
        names = ("mean", "std", "low", "high")
        mean, std, low, high = _numbers(where, _named(where, args, names), 4, "[mean, std, low, high]")
        if std <= 0 or not low < high:
            raise UserInputError(f"{where}: expected std > 0 and low < high")
        if truncated_mass(mean, std, low, high) < MIN_TRUNCATED_MASS:
            raise UserInputError(f"{where}: [low, high] holds almost none of the normal's probability")
        return Parameter(path, "truncated_normal", mean=mean, std=std, low=low, high=high)
    if kind == "choice":
        values, weights = _choice(where, args)
        return Parameter(path, "choice", values, weights)
    raise UserInputError(
        f"parameters.{path}: unknown kind {kind!r}; expected one of: range, linspace, values, uniform, normal, "
        "truncated_normal, choice (or a plain list)"
    )


def check_bounds(parameter: Parameter) -> None:
    """Refuse a parameter whose values or range reach beyond the physical bound of its field (by the unit in
    the field's name, `vrusim.scenario.bounds`), before any variant is built. A normal distribution has no
    range: its draws are checked when the sweep validates its extreme variants."""
    field = parameter.path.rsplit(".", 1)[-1]
    if "[" in field:  # a list element (a path point): its coordinates are checked per variant
        return
    ends = (parameter.low, parameter.high) if parameter.kind in ("uniform", "truncated_normal") else ()
    for value in (*parameter.values, *ends):
        reason = bound_excess(field, value)
        if reason is not None:
            raise UserInputError(f"parameters.{parameter.path}: {reason}")


def parse_correlations(entries: list[CorrelationEntry], parameters: tuple[Parameter, ...]) -> tuple[Correlation, ...]:
    """Check each `correlation` entry against the random parameters; the matrix must be positive definite."""
    order = {p.path: i for i, p in enumerate(parameters) if p.is_random}
    seen: set[frozenset[str]] = set()
    out = []
    for index, entry in enumerate(entries):
        where = f"correlation[{index}].between"
        for path in entry.between:
            if path not in order:
                raise UserInputError(
                    f"{where}: {path!r} is not a random parameter (only parameters drawn from a distribution "
                    "can be correlated; grid parameters and `set` fields cannot)"
                )
        first, second = sorted(entry.between, key=order.__getitem__)
        if first == second:
            raise UserInputError(f"{where}: expected two different parameters")
        if frozenset((first, second)) in seen:
            raise UserInputError(f"{where}: the pair {first}, {second} is given twice")
        seen.add(frozenset((first, second)))
        out.append((first, second, entry.rho))
    correlations = tuple(out)
    if correlations and not is_positive_definite(correlation_matrix(correlations, parameters)[1]):
        raise UserInputError(
            "correlation: these correlations cannot hold together (the correlation matrix is not positive definite)"
        )
    return correlations


def correlation_matrix(
    correlations: tuple[Correlation, ...], parameters: tuple[Parameter, ...]
) -> tuple[list[str], np.ndarray]:
    """The correlated parameters (in spec order) and their correlation matrix (1 on the diagonal, 0 unless given)."""
    named = {path for pair in correlations for path in pair[:2]}
    paths = [p.path for p in parameters if p.path in named]
    matrix = np.eye(len(paths))
    for first, second, rho in correlations:
        i, j = paths.index(first), paths.index(second)
        matrix[i, j] = matrix[j, i] = rho
    return paths, matrix


def is_positive_definite(matrix: np.ndarray) -> bool:
    """True when the Cholesky factorisation exists."""
    try:
        np.linalg.cholesky(matrix)
    except np.linalg.LinAlgError:
        return False
    return True


def spec_from_mapping(data: Any, source: str, folder: Path) -> SweepSpec:
    """Validate a parsed YAML sweep document; relative base paths resolve against `folder`."""
    if not isinstance(data, dict):
        raise UserInputError(f"{source}: expected a mapping of sweep fields at the top level")
    try:
        document = SpecFile.model_validate(data)
    except ValidationError as error:
        raise UserInputError(describe_validation_error(error, source, "sweep spec")) from None
    parameters = tuple(parse_parameter(str(path), value) for path, value in document.parameters.items())
    clash = sorted(set(document.set) & set(document.parameters))
    if clash:
        raise UserInputError(f"set.{clash[0]}: a field is either fixed (set) or swept (parameters), not both")
    check_overlaps([p.path for p in parameters], list(map(str, document.set)))
    for parameter in parameters:
        check_bounds(parameter)
    grid_points = math.prod(len(p.values) for p in parameters if not p.is_random)
    check_limit("sweep_variants", document.samples, "samples")
    check_limit("sweep_variants", grid_points * document.samples, f"samples x {grid_points:,} grid points")
    correlations = parse_correlations(document.correlation, parameters)
    base_file = None if document.base is None else check_name(folder / document.base, f"{source}: base")
    return SweepSpec(
        name=document.name or Path(source).stem,
        description=document.description,
        base_file=base_file,
        catalogue=document.catalogue,
        overrides=dict(document.set),
        parameters=parameters,
        samples=document.samples,
        seed=document.seed,
        batch_size=document.batch_size,
        source=data,
        correlations=correlations,
    )


def check_batch_size(batch_size: int | None) -> None:
    """Refuse a `--batch-size` outside 1 … MAX_BATCH_SIZE (the spec field's range)."""
    if batch_size is not None and not 1 <= batch_size <= MAX_BATCH_SIZE:
        raise UserInputError(f"--batch-size: expected 1 … {MAX_BATCH_SIZE:,} variants per batch, got {batch_size}")


def with_seed(spec: SweepSpec, seed: int) -> SweepSpec:
    """The spec with another master seed, as if its YAML said `seed: <seed>`."""
    return replace(spec, seed=seed, source={**spec.source, "seed": seed})


def load_spec(path: str | Path) -> SweepSpec:
    """Read and validate a sweep spec YAML file."""
    path = Path(path)
    return spec_from_mapping(read_yaml_file(path, "sweep spec"), str(path), path.parent)
