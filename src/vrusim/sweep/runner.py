"""Run a sweep end to end: plan, check, store, execute the missing batches, verify every variant is there once."""

from __future__ import annotations

import hashlib
import json
import platform
import subprocess
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa

from vrusim.errors import UserInputError
from vrusim.io.paths import check_name
from vrusim.planners.registry import plugin_source
from vrusim.scenario.loading import scenario_from_mapping
from vrusim.sweep.chunk import ChunkTask
from vrusim.sweep.chunk_checks import checked_batches
from vrusim.sweep.design import design_rows, make_design
from vrusim.sweep.execute import connect_dask, cpu_count, run_dask, run_in_process, run_processes
from vrusim.sweep.plan import PlannedSweep, SweepPlan, check_budgets, make_plan
from vrusim.sweep.preflight import Preflight, preflight
from vrusim.sweep.spec import Parameter, SweepSpec, check_batch_size
from vrusim.sweep.store import SweepStore, check_exactly_once
from vrusim.sweep.tables import chunk_table, design_types
from vrusim.version import __version__, source_digest

Progress = Callable[[int, int], None]
"""Called with (variants finished, variants in the sweep) after each batch."""


@dataclass
class SweepResult:
    """What a `run_sweep` call did."""

    folder: Path
    variants: int
    chunks: int
    chunks_run: int
    chunks_reused: int
    variants_run: int
    elapsed_s: float
    warnings: list[str] = field(default_factory=list)

    @property
    def variants_per_s(self) -> float:
        """Variants simulated and stored by this call per second of its wall time (planning included)."""
        return self.variants_run / self.elapsed_s if self.elapsed_s > 0 else 0.0


def plan_planners(plan: SweepPlan) -> list[str]:
    """Every planner name the variants of `plan` can use: the bases' and any swept `planner.name` values."""
    names = {base["planner"]["name"] for base in plan.bases.values()}
    for parameter in plan.parameters:
        if parameter.path == "planner.name":
            names.update(str(value) for value in parameter.values)
    return sorted(names)


def plugin_sources(plan: SweepPlan) -> list[dict[str, str | None]]:
    """Module, file and SHA-256 of each plug-in planner of the plan (built-ins are covered by source_sha256)."""
    return [info for name in plan_planners(plan) if (info := plugin_source(name)) is not None]


def code_version() -> dict[str, Any]:
    """The code that produced the results: package version, source digest, git commit if any, libraries."""
    import numba

    source = Path(__file__).resolve().parent.parent
    version: dict[str, Any] = {
        "vrusim": __version__,
        "source_sha256": source_digest(),
        "python": platform.python_version(),
        "numpy": np.__version__,
        "numba": numba.__version__,
        "pyarrow": pa.__version__,
    }
    try:
        commit = subprocess.run(
            ["git", "-C", str(source), "rev-parse", "HEAD"], capture_output=True, text=True, timeout=5, check=True
        ).stdout.strip()
        version["git_commit"] = commit
    except (OSError, subprocess.SubprocessError):
        pass
    return version


def plan_from_manifest(manifest: dict[str, Any]) -> SweepPlan:
    """The plan recorded in a manifest (checked by `read_manifest`): its digest compared before it is rebuilt,
    so an edited plan is one message, never an error of the rebuilding."""
    data = manifest["plan"]
    text = json.dumps(data, sort_keys=True, separators=(",", ":"), allow_nan=True)
    if hashlib.sha256(text.encode()).hexdigest() != manifest["plan_sha256"]:
        raise UserInputError("manifest.json: the recorded plan does not match its digest (was it edited?)")
    parameters = tuple(Parameter.from_description(p) for p in data["parameters"])
    correlations = tuple((first, second, float(rho)) for first, second, rho in data.get("correlations", []))
    columns = tuple((name, tuple(values)) for name, values in data.get("base_columns", []))
    plan = SweepPlan(
        data["name"],
        data["bases"],
        parameters,
        data["samples"],
        data["seed"],
        data["batch_size"],
        correlations,
        columns,
    )
    if plan.digest() != manifest["plan_sha256"]:  # pragma: no cover (a plan vrusim cannot describe back)
        raise UserInputError("manifest.json: the recorded plan does not match its digest (was it edited?)")
    return plan


def local_workers(requested: int, compiled: bool) -> int:
    """Local worker processes for a sweep: `requested`, or with 0 one per core, except that batches which all run
    the compiled step run in this process on every core (threads: the same speed without a process per core
    to start and hold in memory)."""
    if requested > 0:
        return requested
    return 1 if compiled else cpu_count()


Source = SweepSpec | PlannedSweep
"""What a sweep is made from: a spec, or a plan built elsewhere (an OpenSCENARIO parameter distribution)."""


def plan_of(spec: Source, batch_size: int | None = None) -> SweepPlan:
    """The plan of a spec (`make_plan`) or of a planned sweep (at `batch_size` when given)."""
    if isinstance(spec, SweepSpec):
        return make_plan(spec, batch_size)
    check_batch_size(batch_size)
    plan = spec.plan if batch_size is None else replace(spec.plan, batch_size=batch_size)
    check_budgets(plan, [scenario_from_mapping(next(iter(plan.bases.values())), plan.name)])
    return plan


def _base(spec: Source, plan: SweepPlan) -> str:
    if isinstance(spec, PlannedSweep):
        return str(spec.base_file)
    return "catalogue" if plan.tests else str(spec.base_file)


def _described(spec: Source, plan: SweepPlan) -> list[dict[str, Any]]:
    """The manifest's `parameters`: the plan's, then a planned sweep's base columns."""
    return [p.describe() for p in plan.parameters] + (list(spec.columns) if isinstance(spec, PlannedSweep) else [])


def dry_run(spec: Source, batch_size: int | None = None) -> dict[str, Any]:
    """Plan, draw and check a sweep without running it: counts and each parameter's drawn range (JSON-ready)."""
    plan = plan_of(spec, batch_size)
    design = make_design(plan)
    checked = preflight(plan, design).checked
    parameters = []
    for p in plan.parameters:
        column = design[p.path]
        entry = p.describe()
        if column.dtype.kind in "fi":
            entry.update(drawn_min=float(column.min()), drawn_max=float(column.max()))
        parameters.append(entry)
    correlations = [
        {
            "between": [first, second],
            "rho": rho,
            "drawn_rank_correlation": rank_correlation(design[first], design[second]),
        }
        for first, second, rho in plan.correlations
    ]
    return {
        "name": plan.name,
        "base": _base(spec, plan),
        "tests": len(plan.tests),
        "variants": plan.variants,
        "grid_points": plan.grid_points,
        "samples": plan.samples,
        "batch_size": plan.batch_size,
        "batches": plan.chunks,
        "seed": plan.seed,
        "parameters": parameters + (list(spec.columns) if isinstance(spec, PlannedSweep) else []),
        "correlations": correlations,
        "variants_checked": checked,
    }


def rank_correlation(a: np.ndarray, b: np.ndarray) -> float | None:
    """Spearman's rank correlation of two numeric columns (None when either is not numeric or is constant)."""
    if a.dtype.kind not in "fi" or b.dtype.kind not in "fi" or a.size < 2:
        return None
    ranks = [np.argsort(np.argsort(column, kind="stable"), kind="stable") for column in (a, b)]
    if any(r.std() == 0 for r in ranks):  # pragma: no cover (a single variant)
        return None
    return float(np.corrcoef(*ranks)[0, 1])


def _tasks(plan: SweepPlan, design: dict[str, np.ndarray], pending: list[int]):
    digest, types = plan.digest(), design_types(design)
    for index in pending:
        start, stop = plan.chunk_range(index)
        yield ChunkTask(plan, digest, index, design_rows(design, start, stop), types)


def _open(
    spec: Source | None,
    store: SweepStore,
    resume: bool,
    batch_size: int | None,
    warnings: list[str],
    replace: bool = False,
) -> tuple[SweepPlan, dict[str, np.ndarray], Preflight | None]:
    """The plan and design of a new sweep (checked, its folder created: with the preflight's findings) or of the
    one being resumed (compared with what the folder holds)."""
    if not resume:
        if spec is None:
            raise UserInputError("SPEC: a sweep spec file is needed (only --resume can do without)")
        plan = plan_of(spec, batch_size)
        design = make_design(plan)
        checked = preflight(plan, design)
        manifest = {
            "name": plan.name,
            "created_utc": datetime.now(UTC).isoformat(timespec="seconds"),
            "spec": spec.source,
            "base_file": None if spec.base_file is None else str(spec.base_file.resolve()),
            "variants": plan.variants,
            "grid_points": plan.grid_points,
            "samples": plan.samples,
            "batch_size": plan.batch_size,
            "chunks": plan.chunks,
            "seed": plan.seed,
            "parameters": _described(spec, plan),
            "plan": plan.describe(),
            "plan_sha256": plan.digest(),
            "code": {**code_version(), "planner_plugins": plugin_sources(plan)},
        }
        store.create(manifest, chunk_table(design, design_types(design), {}), replace)
        return plan, design, checked
    manifest = store.manifest()
    plan = plan_from_manifest(manifest)
    if batch_size is not None and batch_size != plan.batch_size:
        raise UserInputError(f"--batch-size: the sweep being resumed uses {plan.batch_size}; give that or nothing")
    if spec is not None and plan_of(spec, plan.batch_size).digest() != plan.digest():
        raise UserInputError(
            f"SPEC: differs from the sweep recorded in {store.manifest_path} (spec, base scenario or seed changed); "
            "resume without SPEC, or start a new folder"
        )
    design = make_design(plan)
    if not store.design().equals(chunk_table(design, design_types(design), {})):
        raise UserInputError(f"{store.folder}: the design drawn now differs from the stored one (library change?)")
    if manifest.get("code", {}).get("source_sha256") != source_digest():
        warnings.append("the code changed since the sweep started; resumed batches may differ from the earlier ones")
    recorded = {info["planner"]: info for info in manifest.get("code", {}).get("planner_plugins", [])}
    for info in plugin_sources(plan):
        if recorded.get(info["planner"], {}).get("sha256") != info["sha256"]:
            warnings.append(
                f"planner {info['planner']!r}: its module {info['module']} ({info['file']}) changed since the sweep "
                "started; resumed batches may differ from the earlier ones"
            )
    return plan, design, None


def run_sweep(
    spec: Source | None,
    out: str | Path,
    workers: int = 1,
    scheduler: str | None = None,
    batch_size: int | None = None,
    resume: bool = False,
    progress: Progress | None = None,
    replace: bool = False,
) -> SweepResult:
    """Run (or resume) a sweep into `out` (`replace`: a previous sweep's results there are deleted once the new
    sweep is planned and checked); returns counts and timing. Bad input raises UserInputError, before anything is
    written when it can be found then (the folder, the spec, the scheduler); a new sweep that fails before its
    first batch is stored leaves nothing behind (docs/errors.md). `workers`: local processes; 0 chooses
    (`local_workers`)."""
    if workers < 0:
        raise UserInputError("--workers: expected a positive number of worker processes (0: automatic)")
    started = time.perf_counter()
    store = SweepStore(check_name(out, "--out"))
    if not resume:
        store.check_new(replace)
    client = connect_dask(scheduler) if scheduler is not None else None  # before the output folder is made
    try:
        return _run(spec, store, client, workers, batch_size, resume, progress, replace, started)
    finally:
        if client is not None:
            client.close()


def _run(
    spec: Source | None,
    store: SweepStore,
    client: Any,
    workers: int,
    batch_size: int | None,
    resume: bool,
    progress: Progress | None,
    replace: bool,
    started: float,
) -> SweepResult:
    warnings: list[str] = []
    plan, design, checked = _open(spec, store, resume, batch_size, warnings, replace)
    if workers == 0 and client is None:
        workers = local_workers(0, (checked or preflight(plan, design)).compiled)
    try:
        pending, finished, done_variants = _execute(plan, design, store, client, workers, progress)
    except UserInputError:
        if not resume and not store.finished():  # nothing worth resuming: leave no trace of this run
            store.discard()
        raise
    _, duplicated, missing = check_exactly_once(store.variant_ids(), plan.variants)
    if duplicated or missing:  # pragma: no cover (a bug: batches are written once, atomically)
        raise RuntimeError(f"{store.folder}: {duplicated} variants stored twice, {missing} missing")
    already_done = sum(np.subtract(*reversed(plan.chunk_range(i))) for i in finished)
    return SweepResult(
        store.folder,
        plan.variants,
        plan.chunks,
        len(pending),
        len(finished),
        int(done_variants - already_done),
        time.perf_counter() - started,
        warnings,
    )


def _execute(
    plan: SweepPlan,
    design: dict[str, np.ndarray],
    store: SweepStore,
    client: Any,
    workers: int,
    progress: Progress | None,
) -> tuple[list[int], set[int], int]:
    """Run the batches missing from `store`, writing each as it finishes: (pending, finished before, variants
    done now in all)."""
    store.clean_temporary()
    finished = checked_batches(store.batch_files(), plan.chunks, plan.chunk_range, plan.digest())
    pending = [i for i in range(plan.chunks) if i not in finished]
    done_variants = sum(np.subtract(*reversed(plan.chunk_range(i))) for i in finished)
    if progress:
        progress(int(done_variants), plan.variants)

    def on_done(task: ChunkTask, table: pa.Table) -> None:
        nonlocal done_variants
        store.write_chunk(task.index, table, task.plan_digest)
        done_variants += table.num_rows
        if progress:
            progress(int(done_variants), plan.variants)

    tasks = _tasks(plan, design, pending)
    if client is not None:
        run_dask(tasks, client, on_done)
    elif workers == 1 or len(pending) <= 1:  # one batch: spawning a worker would only add its start-up
        run_in_process(tasks, on_done)
    else:
        run_processes(tasks, workers, on_done)
    return pending, finished, int(done_variants)
