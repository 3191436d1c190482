"""Analysis of a sweep's results directory: collision probability and metric statistics, overall and per group.

    RESULTS/manifest.json                     {"format": "vrusim-sweep/1", "parameters": [{"name": ...}], "chunks": C}
    RESULTS/chunks/chunk-000000.parquet …     one row per variant: parameters by dotted path, `collided`, metrics

DuckDB reads the finished chunk files (names starting with "." are temporary and ignored; a sweep still
running gives "k of C chunks (partial)"). Groups are formed by parameters: one with more distinct values than
`bins` is cut into `bins` equal-width bins over its observed range, otherwise grouped by value. Per group:
runs, collisions, P(collision) with its Wilson 95 % interval, and per metric the count of non-null values,
mean, sample standard deviation, min, p5, median, p95 and max (quantile_cont: linear interpolation).
See docs/sweep_analysis.md.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from decimal import Decimal
from pathlib import Path
from typing import Any

import duckdb

from vrusim.errors import UserInputError
from vrusim.io.paths import check_name
from vrusim.studies.compare import wilson_interval
from vrusim.sweep.chunk_checks import PLAN_KEY, foreign_message
from vrusim.sweep.manifest import MANIFEST, read_manifest

CHUNKS_FOLDER = "chunks"
DEFAULT_BINS = 10
DEFAULT_METRICS = ("min_ttc_s", "impact_ego_speed_mps", "safety", "efficiency", "comfort")
"""Metrics reported when none are chosen (those of them present in the results)."""
STATISTICS = ("count", "mean", "std", "min", "p5", "median", "p95", "max")
"""Per-metric statistics, in output order."""
QUANTILES = (0.05, 0.5, 0.95)
OUTCOME_COLUMN = "collided"
NON_METRIC_COLUMNS = ("variant", "seed", OUTCOME_COLUMN, "outcome", "test")
"""Columns that are neither parameters nor metrics."""
EXTRA_GROUP_COLUMNS = ("test",)
"""Non-parameter columns that may also be grouped by, when present."""
_NUMERIC_TYPES = frozenset(
    {"TINYINT", "SMALLINT", "INTEGER", "BIGINT", "HUGEINT", "FLOAT", "DOUBLE"}
    | {"UTINYINT", "USMALLINT", "UINTEGER", "UBIGINT", "UHUGEINT"}
)


def quote(name: str) -> str:
    """A column name as a DuckDB identifier (dots, brackets and quotes kept literally)."""
    return '"' + name.replace('"', '""') + '"'


def is_numeric(duckdb_type: str) -> bool:
    """Whether a DuckDB column type is a number (integers, floats, decimals; not BOOLEAN)."""
    return duckdb_type in _NUMERIC_TYPES or duckdb_type.startswith("DECIMAL")


def bin_edges(low: float, high: float, bins: int) -> list[float]:
    """`bins` + 1 equal-width edges from `low` to `high` (both exact)."""
    width = (high - low) / bins
    return [low, *(min(low + i * width, high) for i in range(1, bins)), high]


def _connect() -> duckdb.DuckDBPyConnection:
    return duckdb.connect(":memory:")


def _source() -> str:
    return "read_parquet($files, union_by_name = true)"


def _run(con: duckdb.DuckDBPyConnection, sql: str, files: Sequence[Path], where: Path) -> list[tuple]:
    """Rows of a query over the chunk files; a file DuckDB cannot read is a user error naming the folder."""
    try:
        return con.execute(sql, {"files": [str(path) for path in files]}).fetchall()
    except duckdb.Error as error:
        detail = str(error).strip().splitlines()[0]
        raise UserInputError(f"{where}: cannot read the chunk files ({detail})") from None


# ----------------------------------------------------------------------------------------------- the directory


@dataclass(frozen=True)
class SweepResults:
    """A results directory as found now: its manifest, its finished chunk files and their columns."""

    directory: Path
    manifest: dict[str, Any]
    chunk_files: tuple[Path, ...]
    columns: dict[str, str]
    """Column name → DuckDB type, over all chunk files."""
    parameters: tuple[str, ...]
    """Parameter names from the manifest, in its order."""

    @property
    def chunks_expected(self) -> int | None:
        """C from the manifest (None when it does not say)."""
        value = self.manifest.get("chunks")
        return value if isinstance(value, int) and not isinstance(value, bool) and value >= 0 else None

    @property
    def partial(self) -> bool:
        """Whether fewer chunk files exist than the manifest announces."""
        expected = self.chunks_expected
        return expected is not None and len(self.chunk_files) < expected

    @property
    def status(self) -> str:
        """'k of C chunks', with ' (partial)' for a running or interrupted sweep."""
        found, expected = len(self.chunk_files), self.chunks_expected
        if expected is None:
            return f"{found} chunk{'s' if found != 1 else ''}"
        return f"{found} of {expected} chunks" + (" (partial)" if self.partial else "")

    @property
    def groupable(self) -> tuple[str, ...]:
        """Columns one may group by: the parameters present in the chunks, then `test` when present."""
        present = tuple(name for name in self.parameters if name in self.columns)
        return present + tuple(name for name in EXTRA_GROUP_COLUMNS if name in self.columns)

    @property
    def metrics(self) -> tuple[str, ...]:
        """Numeric columns that are neither parameters nor identifiers, in file order."""
        skip = set(self.parameters) | set(NON_METRIC_COLUMNS)
        return tuple(name for name, kind in self.columns.items() if name not in skip and is_numeric(kind))

    def parameter_kind(self, name: str) -> str | None:
        """The manifest's `kind` of a parameter (None for `test` or when not given)."""
        for entry in self.manifest["parameters"]:
            if entry["name"] == name:
                kind = entry.get("kind")
                return kind if isinstance(kind, str) else None
        return None

    def check_group(self, name: str, option: str = "--by") -> str:
        """`name` if it can be grouped by, else a UserInputError naming `option` and listing the choices."""
        if name in self.groupable:
            return name
        if name in self.parameters:
            raise UserInputError(f"{option}: parameter {name!r} is in {MANIFEST} but in no chunk file")
        choices = ", ".join(self.groupable) or "none (the sweep has no parameters)"
        raise UserInputError(f"{option}: unknown parameter {name!r}; expected one of: {choices}")

    def check_metric(self, name: str, option: str = "--metrics") -> str:
        """`name` if it is a metric, else a UserInputError naming `option` and listing the metrics."""
        if name in self.metrics:
            return name
        choices = ", ".join(self.metrics) or "none (the chunk files have no numeric metric columns)"
        raise UserInputError(f"{option}: unknown metric {name!r}; expected one of: {choices}")


def chunk_files(directory: Path) -> list[Path]:
    """The finished chunk files, sorted by name (temporary files, named with a leading '.', are skipped)."""
    folder = directory / CHUNKS_FOLDER
    if not folder.is_dir():
        return []
    return sorted(p for p in folder.iterdir() if p.suffix == ".parquet" and not p.name.startswith(".") and p.is_file())


def _open(directory: str | Path, con: duckdb.DuckDBPyConnection) -> SweepResults:
    directory = check_name(directory, "RESULTS")
    if not directory.exists():
        raise UserInputError(f"{directory}: results directory not found")
    if not directory.is_dir():
        raise UserInputError(f"{directory}: expected a sweep results directory, got a file")
    manifest = read_manifest(directory)
    files = chunk_files(directory)
    if not files:
        raise UserInputError(
            f"{directory}: no chunk files ({CHUNKS_FOLDER}/chunk-*.parquet); the sweep has not finished a batch yet"
        )
    described = _run(con, f"DESCRIBE SELECT * FROM {_source()}", files, directory / CHUNKS_FOLDER)
    columns = {row[0]: row[1] for row in described}
    if OUTCOME_COLUMN not in columns:
        raise UserInputError(f"{directory / CHUNKS_FOLDER}: the chunk files have no {OUTCOME_COLUMN!r} column")
    _check_files(con, directory, manifest, files, columns)
    parameters = tuple(entry["name"] for entry in manifest["parameters"])
    return SweepResults(directory, manifest, tuple(files), columns, parameters)


def _check_files(
    con: duckdb.DuckDBPyConnection, directory: Path, manifest: dict[str, Any], files: list[Path], columns: dict
) -> None:
    """Refuse more chunk files than the manifest announces, a file of another sweep (`chunk_checks`) and a
    float column holding NaN or infinity (vrusim writes NULL for an absent value), naming the file."""
    expected = manifest.get("chunks")
    if expected is not None and len(files) > expected:
        raise UserInputError(
            f"{directory / CHUNKS_FOLDER}: {len(files)} chunk files, but {MANIFEST} announces {expected}; remove "
            "the files that do not belong to this sweep"
        )
    digest = manifest.get("plan_sha256")
    if digest is not None:
        sql = "SELECT file_name, decode(value) FROM parquet_kv_metadata($files) WHERE key = $key"
        key = PLAN_KEY.decode()
        try:
            rows = con.execute(sql, {"files": [str(f) for f in files], "key": key}).fetchall()
        except duckdb.Error as error:
            detail = str(error).strip().splitlines()[0]
            raise UserInputError(f"{directory / CHUNKS_FOLDER}: cannot read the chunk files ({detail})") from None
        for name, recorded in rows:
            if recorded != digest:
                raise UserInputError(foreign_message(Path(name), recorded, digest))
    floats = [name for name, kind in columns.items() if kind in ("DOUBLE", "FLOAT")]
    if floats:
        test = " OR ".join(f"NOT isfinite({quote(name)})" for name in floats)
        picked = ", ".join(f"NOT isfinite({quote(name)})" for name in floats)
        source = "read_parquet($files, union_by_name = true, filename = true)"
        found = _run(con, f"SELECT filename, {picked} FROM {source} WHERE {test} LIMIT 1", files, directory)
        if found:
            column = next(name for name, bad in zip(floats, found[0][1:], strict=True) if bad)
            raise UserInputError(f"{found[0][0]}: column {column} holds NaN or infinity, which vrusim never writes")


def open_results(directory: str | Path) -> SweepResults:
    """Check a results directory (manifest, chunk files, outcome column) and describe what it holds."""
    con = _connect()
    try:
        return _open(directory, con)
    finally:
        con.close()


# ----------------------------------------------------------------------------------------------- summary


def _plain(value: Any) -> Any:
    """A DuckDB value as plain JSON data."""
    if isinstance(value, Decimal):
        return float(value)
    return value


OUTCOME_COUNTS = 4
"""Leading aggregates of `_aggregates`: runs, collisions, stalled, incomplete."""


def _outcome_fields(runs: int, collisions: int, stalled: int | None, incomplete: int | None) -> dict[str, Any]:
    """Runs, collisions, P(collision) and its Wilson 95 % interval; the stalled and incomplete runs (None in
    results written before outcomes existed)."""
    low, high = wilson_interval(collisions, runs)
    return {
        "runs": runs,
        "collisions": collisions,
        "collision_probability": collisions / runs if runs else None,
        "collision_probability_95": [low, high],
        "stalled": stalled,
        "incomplete": incomplete,
    }


def _aggregates(metrics: Sequence[str], has_outcome: bool) -> str:
    """SELECT list: runs, collisions, stalled and incomplete runs (NULL without an `outcome` column), then six
    aggregates per metric (count, mean, std, min, quantiles, max)."""
    parts = ["count(*)", f"count(*) FILTER (WHERE {quote(OUTCOME_COLUMN)})"]
    for outcome in ("stalled", "incomplete"):
        parts.append(f"count(*) FILTER (WHERE {quote('outcome')} = '{outcome}')" if has_outcome else "NULL")
    quantiles = ", ".join(repr(q) for q in QUANTILES)
    for name in metrics:
        value = f"CAST({quote(name)} AS DOUBLE)"
        parts += [
            f"count({value})",
            f"avg({value})",
            f"stddev_samp({value})",
            f"min({value})",
            f"quantile_cont({value}, [{quantiles}])",
            f"max({value})",
        ]
    return ", ".join(parts)


def _metric_fields(metrics: Sequence[str], values: Sequence[Any]) -> dict[str, dict[str, Any]]:
    out = {}
    for index, name in enumerate(metrics):
        count, mean, std, low, quantiles, high = values[6 * index : 6 * index + 6]
        p5, median, p95 = quantiles if quantiles is not None else (None, None, None)
        out[name] = dict(zip(STATISTICS, (count, mean, std, low, p5, median, p95, high), strict=True))
    return out


def _bin_case(name: str, edges: Sequence[float]) -> str:
    """SQL for the bin index of a value: i where edges[i] <= value < edges[i+1]; the last bin holds the maximum."""
    column = quote(name)
    tests = [f"WHEN {column} IS NULL THEN NULL"]
    tests += [f"WHEN {column} < CAST('{edge!r}' AS DOUBLE) THEN {i}" for i, edge in enumerate(edges[1:-1])]
    return f"CASE {' '.join(tests)} ELSE {len(edges) - 2} END"


def _describe_groups(
    con: duckdb.DuckDBPyConnection, results: SweepResults, by: Sequence[str], bins: int
) -> list[dict[str, Any]]:
    """Per grouping column: its type, distinct count, observed range and, when binned, the bin edges."""
    if not by:
        return []
    parts = []
    for name in by:
        column = quote(name)
        parts += [f"count(DISTINCT {column})", f"min({column})", f"max({column})"]
    row = _run(con, f"SELECT {', '.join(parts)} FROM {_source()}", results.chunk_files, results.directory)[0]
    described = []
    for index, name in enumerate(by):
        distinct, low, high = row[3 * index : 3 * index + 3]
        kind = results.columns[name]
        binned = is_numeric(kind) and distinct > bins
        low, high = _plain(low), _plain(high)
        described.append(
            {
                "name": name,
                "kind": results.parameter_kind(name),
                "type": kind,
                "distinct": distinct,
                "binned": binned,
                "low": low if is_numeric(kind) else None,
                "high": high if is_numeric(kind) else None,
                "edges": bin_edges(float(low), float(high), bins) if binned else None,
            }
        )
    return described


def _key(described: dict[str, Any], value: Any) -> Any:
    """A group's value of one grouping column: the value itself, or its bin (index, low, high, centre)."""
    if not described["binned"] or value is None:
        return _plain(value)
    edges = described["edges"]
    low, high = edges[value], edges[value + 1]
    return {"bin": value, "low": low, "high": high, "centre": (low + high) / 2}


def summarize(
    results: str | Path | SweepResults,
    by: Iterable[str] = (),
    bins: int = DEFAULT_BINS,
    metrics: Iterable[str] | None = None,
) -> dict[str, Any]:
    """Collision probability and metric statistics of a sweep, overall and per group of `by` (plain data).

    `results` is a results directory (or an opened one); `metrics` None takes the defaults that are present.
    Raises UserInputError naming the option (--by, --bins, --metrics) for bad choices.
    """
    if isinstance(bins, bool) or not isinstance(bins, int) or bins < 1:
        raise UserInputError(f"--bins: expected a whole number of bins ≥ 1, got {bins!r}")
    con = _connect()
    try:
        if not isinstance(results, SweepResults):
            results = _open(results, con)
        by = [results.check_group(name) for name in dict.fromkeys([by] if isinstance(by, str) else by)]
        if metrics is None:
            chosen = [name for name in DEFAULT_METRICS if name in results.metrics]
        else:
            chosen = [
                results.check_metric(name) for name in dict.fromkeys([metrics] if isinstance(metrics, str) else metrics)
            ]
        described = _describe_groups(con, results, by, bins)
        select = _aggregates(chosen, "outcome" in results.columns)
        overall = _run(con, f"SELECT {select} FROM {_source()}", results.chunk_files, results.directory)[0]
        groups = []
        if by:
            keys = [
                f"{_bin_case(d['name'], d['edges']) if d['binned'] else quote(d['name'])} AS k{i}"
                for i, d in enumerate(described)
            ]
            names = ", ".join(f"k{i}" for i in range(len(by)))
            order = ", ".join(f"k{i} NULLS LAST" for i in range(len(by)))
            sql = f"SELECT {names}, {select} FROM (SELECT *, {', '.join(keys)} FROM {_source()}) GROUP BY {names}"
            for row in _run(con, f"{sql} ORDER BY {order}", results.chunk_files, results.directory):
                key, values = row[: len(by)], row[len(by) :]
                groups.append(
                    {
                        "key": {d["name"]: _key(d, v) for d, v in zip(described, key, strict=True)},
                        **_outcome_fields(*values[:OUTCOME_COUNTS]),
                        "metrics": _metric_fields(chosen, values[OUTCOME_COUNTS:]),
                    }
                )
    finally:
        con.close()
    return {
        "results": str(results.directory),
        "name": results.manifest.get("name"),
        "chunks": {
            "found": len(results.chunk_files),
            "expected": results.chunks_expected,
            "partial": results.partial,
        },
        "status": results.status,
        "bins": bins,
        "by": described,
        "metrics": chosen,
        "overall": {
            **_outcome_fields(*overall[:OUTCOME_COUNTS]),
            "metrics": _metric_fields(chosen, overall[OUTCOME_COUNTS:]),
        },
        "groups": groups,
    }
