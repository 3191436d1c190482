"""`vrusim sweep`: a parameter sweep or Monte Carlo study into a resumable Parquet results folder."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer
from rich.console import Console
from rich.progress import (
    BarColumn,
    MofNCompleteColumn,
    Progress,
    ProgressColumn,
    Task,
    TextColumn,
    TimeElapsedColumn,
    TimeRemainingColumn,
)
from rich.text import Text

from vrusim.cli.options import ForceOption, JsonOption, seed_option
from vrusim.cli.output import console, escape, print_json, user_errors, visible, warn
from vrusim.errors import UserInputError

if TYPE_CHECKING:
    from vrusim.sweep.plan import PlannedSweep
    from vrusim.sweep.spec import SweepSpec

INTERRUPTED_EXIT_CODE = 130
"""Exit code after Ctrl-C (128 + SIGINT), as a shell reports it."""


class RateColumn(ProgressColumn):
    """Variants per second over the recent batches."""

    def render(self, task: Task) -> Text:
        speed = task.finished_speed or task.speed
        return Text("–" if speed is None else f"{speed:,.0f} variants/s", style="progress.data.speed")


def sweep_command(
    spec_file: Annotated[
        str | None,
        typer.Argument(
            metavar="[SPEC.yaml|NAME|DIST.xosc]",
            help="Sweep spec file, a bundled one (`vrusim examples`, e.g. example:pedestrian-monte-carlo), or an "
            "OpenSCENARIO parameter distribution file (<ParameterValueDistribution>); not needed with --resume.",
            show_default=False,
        ),
    ] = None,
    out: Annotated[
        Path,
        typer.Option(
            "--out",
            metavar="DIR",
            help="Results folder: new or empty, the one to --resume, or a previous sweep's to replace with --force.",
        ),
    ] = Path("sweep-results"),
    force: ForceOption = False,
    seed: Annotated[int | None, seed_option("Master seed of the draws. Default: the spec's.")] = None,
    workers: Annotated[
        int,
        typer.Option(
            "--workers",
            help="Local worker processes. Default: this process on every core when the built-in planners' compiled "
            "step runs every variant, else one process per core.",
        ),
    ] = 0,
    scheduler: Annotated[
        str | None, typer.Option("--scheduler", metavar="tcp://HOST:PORT", help="Run on this Dask cluster.")
    ] = None,
    batch_size: Annotated[
        int | None, typer.Option("--batch-size", help="Variants per batch (default: the spec's).")
    ] = None,
    resume: Annotated[
        bool, typer.Option("--resume", help="Continue the sweep in --out: run the missing batches.")
    ] = False,
    quiet: Annotated[bool, typer.Option("--quiet", help="No progress bar.")] = False,
    dry_run: Annotated[
        bool, typer.Option("--dry-run", help="Plan, draw and check the variants; run and write nothing.")
    ] = False,
    as_json: JsonOption = False,
) -> None:
    """Run every variant of a sweep spec; results go to OUT/chunks/*.parquet, batch by batch (resumable)."""
    from vrusim.sweep.execute import SweepAbortedError
    from vrusim.sweep.runner import dry_run as plan_only
    from vrusim.sweep.runner import run_sweep

    show = not quiet and not as_json
    with user_errors():
        _check_modes(force, resume, dry_run, seed)
        spec = _spec(spec_file, seed)
        if workers < 0:
            raise UserInputError("--workers: expected a positive number of worker processes (0: automatic)")
        workers = _capped(workers) if scheduler is None else workers
        if dry_run:
            if spec is None:
                raise UserInputError("SPEC: --dry-run needs a sweep spec file")
            _print_plan(plan_only(spec, batch_size), as_json)
            return
        if not resume:
            from vrusim.sweep.store import SweepStore

            SweepStore(out).check_new(replace=force)  # before planning: refuse a folder in use
        bar = Progress(
            TextColumn("[bold]{task.description}"),
            BarColumn(),
            MofNCompleteColumn(),
            RateColumn(),
            TimeElapsedColumn(),
            TextColumn("left"),
            TimeRemainingColumn(),
            console=Console(stderr=True),
            disable=not show,
        )
        task_id = bar.add_task("sweep", total=None)

        def progress(done: int, total: int) -> None:
            if not bar.live.is_started:  # the bar appears once the sweep is planned and checked
                bar.start()
            bar.update(task_id, completed=done, total=total)

        try:
            result = run_sweep(spec, out, workers, scheduler, batch_size, resume, progress, force)
        except KeyboardInterrupt:
            _stop(bar)
            typer.echo(visible(f"Interrupted: {_saved(out)}."), err=True)
            raise typer.Exit(INTERRUPTED_EXIT_CODE) from None
        except SweepAbortedError as error:
            _stop(bar)
            typer.echo(visible(f"Error: {error}; {_saved(out)}."), err=True)
            raise typer.Exit(1) from None
        finally:
            _stop(bar)
    for warning in result.warnings:
        warn(warning)
    document = {
        "folder": str(result.folder),
        "variants": result.variants,
        "batches": result.chunks,
        "batches_run": result.chunks_run,
        "batches_reused": result.chunks_reused,
        "elapsed_s": round(result.elapsed_s, 3),
        "variants_per_s": round(result.variants_per_s, 1),
    }
    if as_json:
        print_json(document)
        return
    console().print(
        f"{result.variants:,} variants in {result.chunks} batches "
        f"({result.chunks_run} run now, {result.chunks_reused} already done) → {escape(result.folder)} "
        f"in {result.elapsed_s:.1f} s ({result.variants_per_s:,.0f} variants/s). "
        f"Summarize with: vrusim summarize {escape(result.folder)}"
    )


def _saved(out: Path) -> str:
    """What a stopped sweep left in `out`: finished batches to --resume, a started sweep, or nothing."""
    from vrusim.sweep.store import SweepStore

    store = SweepStore(out)
    if not store.manifest_path.is_file():
        return "nothing was written"
    try:
        done = len(store.finished())
    except (UserInputError, OSError):
        done = 0
    if done:
        return f"{done} finished batch{'es' if done != 1 else ''} saved in {out}; continue with --resume"
    return f"no batch finished yet in {out}; continue with --resume (it runs them all)"


def _capped(workers: int) -> int:
    """`workers`, at most one per core: each worker process holds its own batches and compiled kernels in memory
    (8 workers on 2 cores peaked at 1.7 GB) and more processes than cores make no batch finish sooner."""
    from vrusim.sweep.execute import cpu_count

    cores = cpu_count()
    if workers > cores:
        warn(f"--workers {workers}: this machine has {cores} cores for this process; using {cores} workers")
        return cores
    return workers


def _stop(bar: Progress) -> None:
    """Stop the progress bar if it was shown (stopping one never started prints an empty line)."""
    if bar.live.is_started:
        bar.stop()


def _check_modes(force: bool, resume: bool, dry_run: bool, seed: int | None) -> None:
    """Options that exclude each other."""
    if force and resume:
        raise UserInputError("--force: replaces the sweep in --out, --resume continues it; give one of them")
    if seed is not None and resume:
        raise UserInputError("--seed: a resumed sweep keeps its seed; give --seed only to start a sweep")
    if force and dry_run:
        raise UserInputError("--force: --dry-run writes nothing, so there is nothing to replace")


def _spec(spec_file: str | None, seed: int | None) -> SweepSpec | PlannedSweep | None:
    """The sweep spec SPEC names (a file or a bundled name), with --seed as its master seed when given; or the
    sweep of an OpenSCENARIO parameter distribution file."""
    if spec_file is None:
        return None
    if spec_file.lower().endswith(".xosc"):
        from vrusim.sweep.xosc_sweep import distribution_sweep

        return distribution_sweep(spec_file, seed)
    from vrusim.sources import sweep_spec_path
    from vrusim.sweep.spec import load_spec, with_seed

    spec = load_spec(sweep_spec_path(spec_file))
    return spec if seed is None else with_seed(spec, seed)


def _counts(plan: dict) -> str:
    """The factors whose product is the variant count (the grid points include the catalogue tests: once)."""
    samples = f"{plan['samples']:,} samples"
    if not plan["tests"]:
        return f"{plan['grid_points']:,} grid points × {samples}"
    if plan["base"].lower().endswith(".xosc"):
        return f"{plan['tests']:,} OpenSCENARIO parameter sets of {plan['base']}"
    values = plan["grid_points"] // plan["tests"]
    return f"{plan['tests']:,} catalogue tests × {values:,} parameter grid points × {samples}"


SHOWN_VALUES = 8
"""A longer list of values is printed as its first and last few and its length (--json gives them all)."""


def _abridged(value: object) -> object:
    """A list of more than SHOWN_VALUES values as its first five, '…', its last two and the count."""
    if not isinstance(value, list) or len(value) <= SHOWN_VALUES:
        return value
    return f"[{', '.join(map(repr, value[:5]))}, …, {', '.join(map(repr, value[-2:]))}] ({len(value):,} values)"


def _print_plan(plan: dict, as_json: bool) -> None:
    if as_json:
        print_json(plan)
        return
    out = console()
    out.print(
        f"{escape(plan['name'])}: {plan['variants']:,} variants ({_counts(plan)}) in {plan['batches']:,} batches of "
        f"{plan['batch_size']:,}; seed {plan['seed']}"
    )
    for p in plan["parameters"]:
        drawn = f"  drawn {p['drawn_min']:.6g} … {p['drawn_max']:.6g}" if "drawn_min" in p else ""
        settings = {k: _abridged(v) for k, v in p.items() if k not in ("name", "kind", "drawn_min", "drawn_max")}
        out.print(f"  {p['name']}: {p['kind']} {settings}{drawn}", markup=False)
    for c in plan["correlations"]:
        ranks = c["drawn_rank_correlation"]
        drawn = "" if ranks is None else f"  drawn rank correlation {ranks:+.3f}"
        out.print(f"  correlation {c['between'][0]} ~ {c['between'][1]}: rho {c['rho']:+g}{drawn}", markup=False)
    out.print(f"{plan['variants_checked']} variants built and checked; nothing run or written (--dry-run).")
