"""Read an OpenSCENARIO parameter value distribution file (`<ParameterValueDistribution>`) into parameter sets.

    <OpenSCENARIO><FileHeader .../><ParameterValueDistribution>
      <ScenarioFile filepath="cpna.xosc"/>                       relative to the distribution file
      <Deterministic> | <Stochastic numberOfTestRuns="N" randomSeed="S">
    </ParameterValueDistribution></OpenSCENARIO>

Deterministic: each `DeterministicSingleParameterDistribution` (a `DistributionSet` of `Element`s, or a
`DistributionRange` from `Range` lowerLimit to upperLimit inclusive in steps of stepWidth) and each
`DeterministicMultiParameterDistribution` (a `ValueSetDistribution` of `ParameterValueSet`s, each a set of
`ParameterAssignment`s) is one dimension; the sets are their full factorial, first dimension slowest.
Stochastic: N runs, each parameter drawn independently from a `UniformDistribution` (`Range`) or a
`NormalDistribution` (expectedValue, variance; an optional `Range` truncates it) with numpy's PCG64 seeded by
randomSeed (0 when absent) and the parameter's name. Other distributions are refused. The number of sets is
checked against the `sweep_variants` and `distribution_variants` limits before any is made.
"""

from __future__ import annotations

import itertools
import math
import zlib
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from vrusim.formats.xml_file import Element
from vrusim.formats.xosc_document import XoscDocument
from vrusim.limits import check_limit

DISTRIBUTION_TAG = "ParameterValueDistribution"
MAX_REJECTION_ROUNDS = 10_000
"""Rounds of redrawing a truncated normal's values that fell outside its range before giving up."""


@dataclass(frozen=True)
class ParameterSets:
    """The parameter sets of a distribution file: the scenario they apply to and one value text per name."""

    source: Path
    scenario_file: Path
    names: tuple[str, ...]
    rows: tuple[tuple[str, ...], ...]
    kind: str
    """"deterministic" or "stochastic"."""


Dimension = list[dict[str, str]]
"""One factor of a deterministic distribution: its alternatives, each a set of parameter values."""


def _range_count(doc: XoscDocument, element: Element) -> tuple[float, float, int]:
    """(lower limit, step, number of values) of a `DistributionRange`."""
    step = doc.number(element, "stepWidth")
    limits = doc.child(element, "Range")
    low, high = doc.number(limits, "lowerLimit"), doc.number(limits, "upperLimit")
    if step <= 0 or high < low:
        raise doc.fail(element, f"needs stepWidth > 0 and lowerLimit <= upperLimit (got {step:g}, {low:g}..{high:g})")
    steps = (high - low) / step * (1 + 1e-12) + 1e-9  # inf for a tiny step: checked before it becomes an int
    count = math.floor(steps) + 1 if math.isfinite(steps) else steps
    check_limit("sweep_variants", count, f"{doc.source}: line {element.line}: <{element.tag}> values")
    return low, step, int(count)


def _range_text(low: float, step: float, index: int) -> str:
    value = float(f"{low + index * step:.12g}")
    return str(int(value)) if value.is_integer() and abs(value) < 2**53 else repr(value)


class _Deterministic:
    """Reads the dimensions of a `<Deterministic>` element; sizes are known before values are made."""

    def __init__(self, doc: XoscDocument, element: Element) -> None:
        self.doc = doc
        self.parts = doc.children(
            element, {"DeterministicSingleParameterDistribution", "DeterministicMultiParameterDistribution"}
        )
        if not self.parts:
            raise doc.fail(element, "has no distribution")

    def sizes(self) -> list[int]:
        return [self._size(part) for part in self.parts]

    def _size(self, part: Element) -> int:
        doc = self.doc
        if part.tag == "DeterministicMultiParameterDistribution":
            distribution = doc.single(part, {"ValueSetDistribution"})
            return len(doc.children(distribution, {"ParameterValueSet"})) or _empty(doc, distribution)
        inner = doc.single(part, {"DistributionSet", "DistributionRange", "UserDefinedDistribution"})
        if inner.tag == "DistributionSet":
            return len(doc.children(inner, {"Element"})) or _empty(doc, inner)
        if inner.tag == "DistributionRange":
            return _range_count(doc, inner)[2]
        raise doc.unsupported(inner, part.tag)

    def dimensions(self) -> list[Dimension]:
        return [self._dimension(part) for part in self.parts]

    def _dimension(self, part: Element) -> Dimension:
        doc = self.doc
        if part.tag == "DeterministicMultiParameterDistribution":
            distribution = part.children[0]
            out = []
            for value_set in doc.children(distribution, {"ParameterValueSet"}):
                assignments = doc.children(value_set, {"ParameterAssignment"})
                out.append({doc.raw(a, "parameterRef"): doc.text(a, "value") for a in assignments})
            return out
        name = doc.raw(part, "parameterName")
        inner = part.children[0]
        if inner.tag == "DistributionSet":
            return [{name: doc.text(e, "value")} for e in inner.children]
        low, step, count = _range_count(doc, inner)
        return [{name: _range_text(low, step, i)} for i in range(count)]


def _check_count(count: float, what: str) -> None:
    """Refuse `count` parameter sets beyond the `sweep_variants` or the (smaller) `distribution_variants` limit:
    each set becomes a whole scenario import, about 3 ms and 25 kB, before any is made."""
    check_limit("sweep_variants", count, what)
    check_limit("distribution_variants", count, what)


def _empty(doc: XoscDocument, element: Element) -> int:
    raise doc.fail(element, "has no values")


def _deterministic(doc: XoscDocument, element: Element) -> tuple[tuple[str, ...], list[tuple[str, ...]]]:
    reader = _Deterministic(doc, element)
    sizes = reader.sizes()
    _check_count(math.prod(sizes), f"{doc.source}: {' x '.join(f'{n:,}' for n in sizes)} parameter sets")
    dimensions = reader.dimensions()
    names: list[str] = []
    for dimension in dimensions:
        keys = list(dimension[0])
        if any(list(alternative) != keys for alternative in dimension):
            raise doc.fail(element, "has a ValueSetDistribution whose sets assign different parameters")
        for key in keys:
            if key in names:
                raise doc.fail(element, f"assigns parameter {key!r} in two distributions")
            names.append(key)
    rows = []
    for combination in itertools.product(*dimensions):
        merged: dict[str, str] = {}
        for alternative in combination:
            merged.update(alternative)
        rows.append(tuple(merged[name] for name in names))
    return tuple(names), rows


def _draws(doc: XoscDocument, element: Element, rng: np.random.Generator, runs: int) -> np.ndarray:
    """`runs` values of one `StochasticDistribution` element."""
    kind = doc.single(element, {"UniformDistribution", "NormalDistribution"} | _REFUSED_STOCHASTIC)
    if kind.tag in _REFUSED_STOCHASTIC:
        raise doc.unsupported(kind, element.tag)
    limits = doc.optional(kind, "Range")
    doc.children(kind, {"Range"})
    low, high = -math.inf, math.inf
    if limits is not None:
        low, high = doc.number(limits, "lowerLimit"), doc.number(limits, "upperLimit")
        if not low <= high:
            raise doc.fail(limits, f"needs lowerLimit <= upperLimit (got {low:g}, {high:g})")
    if kind.tag == "UniformDistribution":
        if limits is None:
            raise doc.fail(kind, "needs a <Range>")
        return rng.uniform(low, high, runs)
    mean, variance = doc.number(kind, "expectedValue"), doc.number(kind, "variance")
    if variance < 0:
        raise doc.fail(kind, f"attribute variance: expected >= 0, got {variance:g}")
    out, missing = np.empty(runs), np.arange(runs)
    for _ in range(MAX_REJECTION_ROUNDS):
        values = rng.normal(mean, math.sqrt(variance), missing.size)
        keep = (values >= low) & (values <= high)
        out[missing[keep]] = values[keep]
        missing = missing[~keep]
        if missing.size == 0:
            return out
    raise doc.fail(kind, "rejects nearly every draw: its Range holds almost none of the distribution")


_REFUSED_STOCHASTIC = {"LogNormalDistribution", "PoissonDistribution", "Histogram", "ProbabilityDistributionSet"}
_REFUSED_STOCHASTIC |= {"UserDefinedDistribution"}


def _stochastic(doc: XoscDocument, element: Element) -> tuple[tuple[str, ...], list[tuple[str, ...]]]:
    runs = doc.number(element, "numberOfTestRuns")
    if not runs.is_integer() or runs < 1:
        raise doc.fail(element, f"attribute numberOfTestRuns: expected a whole number >= 1, got {runs:g}")
    _check_count(runs, f"{doc.source}: line {element.line}: <{element.tag}> numberOfTestRuns")
    seed = doc.number(element, "randomSeed", 0.0)
    if not seed.is_integer() or seed < 0:
        raise doc.fail(element, f"attribute randomSeed: expected a whole number >= 0, got {seed:g}")
    names, columns = [], []
    for part in doc.children(element, {"StochasticDistribution"}):
        name = doc.raw(part, "parameterName")
        if name in names:
            raise doc.fail(part, f"draws parameter {name!r} twice")
        rng = np.random.Generator(np.random.PCG64(np.random.SeedSequence([int(seed), zlib.crc32(name.encode())])))
        names.append(name)
        columns.append([repr(float(v)) for v in _draws(doc, part, rng, int(runs))])
    if not names:
        raise doc.fail(element, "has no <StochasticDistribution>")
    return tuple(names), list(zip(*columns, strict=True))


def is_distribution(root: Element) -> bool:
    """Whether an OpenSCENARIO root element is a parameter value distribution (not a scenario)."""
    return root.first(DISTRIBUTION_TAG) is not None


def read_distribution(root: Element, path: Path) -> ParameterSets:
    """The parameter sets of the distribution document `root` read from `path`."""
    doc = XoscDocument(str(path))
    doc.children(root, {"FileHeader", DISTRIBUTION_TAG})
    distribution = doc.child(root, DISTRIBUTION_TAG)
    doc.children(distribution, {"ScenarioFile", "Deterministic", "Stochastic"})
    scenario = doc.child(distribution, "ScenarioFile")
    name = doc.raw(scenario, "filepath")
    doc.confined_path(scenario, "filepath", path.parent, name, "distribution file")
    scenario_file = path.parent / name  # as written, for messages
    if not scenario_file.is_file() or scenario_file.resolve() == path.resolve():
        raise doc.fail(scenario, f"names {name[:60]!r}, which is not a scenario file next to the distribution file")
    body = [c for c in distribution.children if c.tag != "ScenarioFile"]
    if len(body) != 1:
        raise doc.fail(distribution, "needs exactly one of <Deterministic>, <Stochastic>")
    kind = body[0].tag.lower()
    reader = _deterministic if kind == "deterministic" else _stochastic
    names, rows = reader(doc, body[0])
    return ParameterSets(path, scenario_file, names, tuple(rows), kind)


def iter_sets(sets: ParameterSets) -> Iterator[dict[str, str]]:
    """Each parameter set as a mapping name -> value text, in order."""
    for row in sets.rows:
        yield dict(zip(sets.names, row, strict=True))
