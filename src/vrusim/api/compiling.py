"""`compile_kernels`: compile vrusim's kernels ahead of time (`vrusim compile`), on every core at once.

A command's first run after an install or upgrade compiles the kernels it uses (`vrusim run` about 20 s, `vrusim
ncap --night` about 30 s, on this project's 2-core VM) and keeps them in the kernel cache
(`vrusim.kernels.kernel_cache_folder`, or NUMBA_CACHE_DIR). Compiling them ahead of time moves that wait to
where it costs nothing: a container image's build, a CI job's cache step, an install script.

Numba compiles a kernel for the argument types it is first called with, so kernels are compiled by running what
uses them, briefly, as the commands do. Each planner has up to three parts, run as tasks in a pool of processes
(its grids after its compiled step, in the same process, as they use it):

- `compiled`: the planner's compiled step (`vrusim run`, `paper`, `sweep`, `ncap` without drivers or doors), on
  every bundled scenario for two steps with V2X on;
- `ncap`: the Euro NCAP grids of both editions, day and night, as `vrusim ncap` runs them (their drivers, doors,
  occluding obstacles and contact probes use kernels of their own);
- `per-step`: traces (`vrusim run --trace/--plot/--animate`, `vrusim.run` of one scenario) and the per-step path
  (plug-in planners, the Gymnasium environments): the bundled scenarios with a trace on the per-step path and,
  for a planner with a compiled step, on its traced version, for two steps;
- `threaded`: the per-step path's multi-threaded kernels, which batches of `vrusim.kernels.PARALLEL_MIN_BATCH`
  variants or more run (a plug-in planner's large batches), on that many copies of them.

On a warm cache every task only loads its kernels (about a second each).
"""

from __future__ import annotations

import dataclasses
import multiprocessing
import os
import time
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass

from vrusim.engine.compiled_run import COMPILED_PLANNERS
from vrusim.errors import UserInputError

PARTS = ("compiled", "ncap", "per-step", "threaded")
"""What `compile_kernels` can compile, in the order tasks start (the longest first)."""
COMPILED_STEP_PLANNERS = tuple(COMPILED_PLANNERS.values())
"""The planners with a compiled step (fsm, none, aeb, predictive): the default planners."""
WARM_UP_STEPS = 2
"""Steps each warm-up run takes: enough to call every kernel of a step once."""


@dataclass(frozen=True)
class CompileTask:
    """Some parts for one planner, run in turn in one process."""

    parts: tuple[str, ...]
    planner: str

    @property
    def name(self) -> str:
        """The parts and the planner, e.g. "compiled + ncap (fsm)"."""
        return f"{' + '.join(self.parts)} ({self.planner})"


@dataclass(frozen=True)
class CompileReport:
    """What `compile_kernels` did: the kernel cache folder, and each task's wall time (s) in finishing order."""

    folder: str
    seconds: dict[str, float]
    wall_s: float


def compile_tasks(planners: Sequence[str], parts: Sequence[str]) -> list[CompileTask]:
    """The tasks for `planners` and `parts`, longest first. A planner's Euro NCAP grids run after its compiled
    step, in the same process, as they use it; a part a planner lacks (the compiled step of a low-speed planner)
    is left out."""
    tasks = []
    for planner in planners:
        first = tuple(
            part
            for part in ("compiled", "ncap")
            if part in parts and (part == "ncap" or planner in COMPILED_STEP_PLANNERS)
        )
        tasks += [CompileTask(first, planner)] if first else []
    per_step = tuple(part for part in ("per-step", "threaded") if part in parts)
    return tasks + ([CompileTask(per_step, planner) for planner in planners] if per_step else [])


def _warm_up_scenarios(planner: str) -> list:
    """Every bundled scenario, with `planner` and V2X on."""
    from vrusim.scenario.loading import load_scenario
    from vrusim.scenario.settings import with_settings
    from vrusim.sources import bundled

    return [
        with_settings(load_scenario(entry.path), planner=planner, v2x=True)
        for entry in bundled()
        if entry.kind == "scenario"
    ]


def _run_briefly(scenarios: list, **options) -> None:
    """`simulate` the scenarios as one batch for `WARM_UP_STEPS` steps."""
    import numpy as np

    from vrusim.engine.simulate import simulate
    from vrusim.sim.params import pack

    batch = pack(scenarios)
    steps = dataclasses.replace(
        batch, n_steps=WARM_UP_STEPS, duration_s=np.full(batch.size, WARM_UP_STEPS * batch.dt_s)
    )
    simulate(steps, **options)


def run_task(task: CompileTask) -> float:
    """Run one task in this process (compiling or loading its kernels); its wall time, s."""
    started = time.perf_counter()
    for part in task.parts:
        if part == "compiled":
            _run_briefly(_warm_up_scenarios(task.planner), compiled=True)
        elif part == "ncap":
            from vrusim.api.assessing import euro_ncap

            for protocol in ("2026", "2023"):
                euro_ncap(planner=task.planner, night=True, protocol=protocol)
        elif part == "per-step":
            scenarios = _warm_up_scenarios(task.planner)
            _run_briefly(scenarios, trace=True, compiled=False)  # the per-step path (plug-in planners, the Gym)
            _run_briefly(scenarios, trace=True)  # a planner with a compiled step records its trace in it
        else:
            from vrusim.kernels import PARALLEL_MIN_BATCH

            scenarios = _warm_up_scenarios(task.planner)
            _run_briefly(scenarios * -(-PARALLEL_MIN_BATCH // len(scenarios)), compiled=False)
    return time.perf_counter() - started


def _checked(planners: Sequence[str] | None, parts: Sequence[str] | None, jobs: int | None) -> tuple:
    from vrusim.planners.registry import BUILTIN_PLANNERS

    planners = [planners] if isinstance(planners, str) else planners
    parts = [parts] if isinstance(parts, str) else parts
    planners = list(COMPILED_STEP_PLANNERS if planners is None else dict.fromkeys(planners))
    for name in planners:
        if name not in BUILTIN_PLANNERS:
            raise UserInputError(
                f"planners: expected built-in planner names ({', '.join(BUILTIN_PLANNERS)}), got {name!r} (a "
                "plug-in planner's own code is not vrusim's to compile; its runs use the per-step kernels)"
            )
    parts = list(PARTS if parts is None else dict.fromkeys(parts))
    for part in parts:
        if part not in PARTS:
            raise UserInputError(f"parts: expected some of {', '.join(PARTS)}, got {part!r}")
    if not planners or not parts:
        raise UserInputError("planners, parts: expected at least one of each")
    if jobs is None:
        jobs = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1
    elif isinstance(jobs, bool) or not isinstance(jobs, int) or jobs < 1:
        raise UserInputError(f"jobs: expected a whole number of processes >= 1, got {jobs!r}")
    return planners, parts, jobs


def compile_kernels(
    planners: Sequence[str] | None = None,
    parts: Sequence[str] | None = None,
    jobs: int | None = None,
    on_done: Callable[[CompileTask, float, int, int], None] | None = None,
    on_start: Callable[[list[CompileTask], int], None] | None = None,
) -> CompileReport:
    """Compile (or load, when cached) the kernels that `planners` use in `parts`, in `jobs` processes at once.

    `planners`: built-in planner names, or one (default: the four with a compiled step: fsm, none, aeb,
    predictive). `parts`: some of "compiled", "ncap", "per-step", "threaded", or one (default: all). `jobs`: processes
    (default: the cores this process may use). `on_start(tasks, processes)` is called before the first task
    starts, `on_done(task, seconds, done, total)` as each task ends. Bad arguments raise UserInputError; a task
    that fails raises its error.
    """
    planners, parts, jobs = _checked(planners, parts, jobs)
    from vrusim.kernels import kernels_cached

    if not kernels_cached():
        raise UserInputError(
            "NUMBA_CACHE_DIR: no folder to keep compiled kernels in can be written (the user's cache folder, a "
            "private temporary one, or NUMBA_CACHE_DIR as set); set NUMBA_CACHE_DIR to a writable folder"
        )
    tasks = compile_tasks(planners, parts)
    if not tasks:
        raise UserInputError(
            f"parts: nothing to compile for {', '.join(parts)} with {', '.join(planners)} (only "
            f"{', '.join(COMPILED_STEP_PLANNERS)} have a compiled step)"
        )
    processes = min(jobs, len(tasks))
    if on_start is not None:
        on_start(tasks, processes)
    started = time.perf_counter()
    seconds: dict[str, float] = {}
    context = multiprocessing.get_context("spawn")  # a fresh interpreter: no numba threads inherited by a fork
    with ProcessPoolExecutor(max_workers=processes, mp_context=context) as pool:
        running = {pool.submit(run_task, task): task for task in tasks}
        try:
            for future in as_completed(running):
                task = running[future]
                seconds[task.name] = future.result()
                if on_done is not None:
                    on_done(task, seconds[task.name], len(seconds), len(tasks))
        except BaseException:
            pool.shutdown(wait=False, cancel_futures=True)  # the tasks not started yet do not start
            raise
    import numba

    from vrusim.kernels import kernel_cache_folder

    folder = kernel_cache_folder()
    return CompileReport(
        str(folder) if folder is not None else str(numba.config.CACHE_DIR), seconds, time.perf_counter() - started
    )
