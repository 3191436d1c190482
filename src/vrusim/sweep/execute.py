"""Run sweep batches: in this process, in local worker processes, or on a Dask cluster — same results.

Each finished batch is handed to `on_done` in the calling process (which writes it): in completion order from
workers, in the batches' order when they run in this process.
Local workers are spawned (not forked: the compiled kernels' thread pools do not survive a fork); each gets
an equal share of the cores as numba threads. A worker that dies (killed, out of memory) breaks the local
pool: the pool is restarted and its unfinished batches run again, at most `MAX_POOL_RESTARTS` times. On a
Dask cluster the scheduler itself reruns the batches of a lost worker.
"""

from __future__ import annotations

import multiprocessing
import os
from collections import deque
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, ThreadPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from types import ModuleType
from typing import Any

import pyarrow as pa

from vrusim.errors import UserInputError
from vrusim.extras import extra
from vrusim.io.paths import shown
from vrusim.sweep.chunk import ChunkTask, run_chunk

MAX_POOL_RESTARTS = 3
CONNECT_TIMEOUT_S = 10
"""Seconds to wait for a Dask scheduler to answer."""
IN_FLIGHT_PER_WORKER = 2
"""Batches queued per local worker: keeps workers busy while bounding memory to a few batches each."""
IN_FLIGHT_IN_PROCESS = 2
"""Batches run at once in this process: while one's Python work (reading, packing, tabulating) runs, the other's
kernels, which release the GIL, keep the cores busy."""

OnDone = Callable[[ChunkTask, pa.Table], None]


class SweepAbortedError(Exception):
    """The sweep stopped before every batch finished (the finished ones are saved)."""


def cpu_count() -> int:
    """Cores this process may use."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover (not Linux)
        return os.cpu_count() or 1


def run_in_process(tasks: Iterable[ChunkTask], on_done: OnDone) -> None:
    """Every batch in this process (the kernels use all cores), `IN_FLIGHT_IN_PROCESS` at once on threads;
    `on_done` runs in this thread, in the batches' order. After a batch fails, no new one starts."""
    pending: deque[tuple[ChunkTask, Future]] = deque()
    with ThreadPoolExecutor(IN_FLIGHT_IN_PROCESS, thread_name_prefix="vrusim-batch") as pool:
        try:
            for task in tasks:
                pending.append((task, pool.submit(run_chunk, task)))
                if len(pending) == IN_FLIGHT_IN_PROCESS:
                    done, future = pending.popleft()
                    on_done(done, future.result())
            while pending:
                done, future = pending.popleft()
                on_done(done, future.result())
        except BaseException:
            pool.shutdown(wait=True, cancel_futures=True)
            raise


def _with_threads(task: ChunkTask, threads: int) -> ChunkTask:
    return ChunkTask(task.plan, task.plan_digest, task.index, task.rows, task.types, threads)


def _terminate(pool: ProcessPoolExecutor) -> None:
    processes = list(getattr(pool, "_processes", {}).values())
    pool.shutdown(wait=False, cancel_futures=True)
    for process in processes:
        if process.is_alive():
            process.terminate()


def run_processes(tasks: Iterable[ChunkTask], workers: int, on_done: OnDone) -> None:
    """Every batch on `workers` spawned local processes, a bounded number in flight."""
    threads = max(1, cpu_count() // workers)
    queue: Iterator[ChunkTask] = (_with_threads(task, threads) for task in tasks)
    retry: list[ChunkTask] = []
    restarts = 0
    context = multiprocessing.get_context("spawn")
    while True:
        pool = ProcessPoolExecutor(max_workers=workers, mp_context=context)
        running: dict[Future, ChunkTask] = {}
        try:
            while True:
                while len(running) < workers * IN_FLIGHT_PER_WORKER:
                    task = retry.pop() if retry else next(queue, None)
                    if task is None:
                        break
                    running[pool.submit(run_chunk, task)] = task
                if not running:
                    pool.shutdown()
                    return
                done, _ = wait(running, return_when=FIRST_COMPLETED)
                for future in done:
                    table = future.result()  # raises BrokenProcessPool while the batch is still in `running`
                    on_done(running.pop(future), table)
        except BrokenProcessPool:
            retry.extend(running.values())
            _terminate(pool)
            restarts += 1
            if restarts > MAX_POOL_RESTARTS:
                raise SweepAbortedError(
                    f"worker processes died {restarts} times (out of memory? try a smaller --batch-size)"
                ) from None
        except BaseException:
            _terminate(pool)
            raise


def dask_distributed() -> ModuleType:
    """The `distributed` package, or a UserInputError naming the 'dask' extra (call it before starting)."""
    with extra("dask"):
        import distributed
    return distributed


def connect_dask(scheduler: str) -> Any:
    """A client of the Dask cluster at `scheduler` (tcp://host:port). A malformed or unreachable address is a
    UserInputError naming --scheduler: call it before anything is written."""
    distributed = dask_distributed()
    if not scheduler.strip():
        raise UserInputError("--scheduler: expected the address of a Dask scheduler, e.g. tcp://HOST:PORT")
    try:
        return distributed.Client(scheduler, timeout=f"{CONNECT_TIMEOUT_S}s")
    except Exception as error:  # any refusal of the user's address: malformed, unknown host, nothing listening
        reason = shown(str(error) or type(error).__name__)
        raise UserInputError(
            f"--scheduler: cannot connect to the Dask scheduler at {shown(scheduler)} ({reason})"
        ) from None


def run_dask(tasks: Iterable[ChunkTask], client: Any, on_done: OnDone) -> None:
    """Every batch on the Dask cluster of `client` (`connect_dask`); this process writes the results. The caller
    closes the client."""
    distributed = dask_distributed()
    batches = [_with_threads(task, 1) for task in tasks]
    futures = {
        client.submit(run_chunk, task, key=f"vrusim-{task.plan_digest[:16]}-{task.index}", pure=False): task
        for task in batches
    }
    for future in distributed.as_completed(futures):
        task = futures.pop(future)
        on_done(task, future.result())
        future.release()
