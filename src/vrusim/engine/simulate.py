"""The batch engine: advances B variants in lock-step with a fixed time step.

Each step, from the state at time t: sensing (sector, occlusion → sensor model) → V2X (RSU → channel) → fused
observation → planner → VRU triggers (judged on the ego state at t) and VRU motion to t + dt → ego motion to
t + dt → contact check and streaming metrics (the step itself: vrusim.engine.stepper). A variant stops
contributing to its metrics when it collides (if `stop_on_collision`), completes its route (if
`stop_at_route_end`) or reaches its duration; the loop ends when every variant has stopped.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from vrusim.engine.accumulators import RunMetrics
from vrusim.engine.compiled_run import compiled_support, run_compiled
from vrusim.engine.stepper import BatchStepper, checked_planner_command
from vrusim.engine.trace_recorder import TraceRecorder, check_trace_budget, trace_columns
from vrusim.errors import UserInputError
from vrusim.limits import check_limit
from vrusim.planners.base import (
    Planner,
    PlannerBase,
    planner_door_hold,
    planner_mode,
    planner_mode_names,
    planner_warning,
)
from vrusim.planners.registry import make_planner
from vrusim.scenario.schema import Scenario
from vrusim.sim.compaction import compactable, take
from vrusim.sim.params import BatchParams, pack
from vrusim.sim.sensing.sensor_params import history_depth
from vrusim.sim.v2x.channel_params import queue_slots
from vrusim.sim.v2x.messages import Channel


@dataclass
class BatchRun:
    """Everything a batch run produced: parameters, streamed metrics, planner mode names, optional trace."""

    params: BatchParams
    metrics: RunMetrics
    mode_names: tuple[str, ...]
    trace: dict[str, np.ndarray] | None = None
    steps: int = 0


def _planner_for(planner_names: Sequence[str]) -> Planner:
    names = set(planner_names)
    if len(names) != 1:
        raise UserInputError(f"planner.name: one batch runs one planner, got {sorted(names)}")
    return make_planner(names.pop())


COMPACT_BELOW = 0.8
"""Drop stopped variants from the working set once fewer than this fraction of it are still running."""


def simulate(
    scenarios: Sequence[Scenario] | BatchParams,
    planner: Planner | None = None,
    channel: Channel | None = None,
    trace: bool = False,
    compiled: bool | None = None,
) -> BatchRun:
    """Run scenarios (or an already packed batch) as one batch; return the streamed results and optional trace.

    Without a trace, variants that have stopped are dropped from the working set as the run goes on (if the
    planner, channel and sensor model all have a `compact` method); their results are final by then. A
    planner or channel passed in then ends the run holding only the variants still running at its end.

    `compiled`: None runs a built-in planner's compiled step (`engine.compiled_run`) when the run allows it,
    else the per-step path; a batch that only some variants' drivers or doors keep from the compiled step runs
    those variants per step and the others compiled (`_split_run`). False always takes the per-step path
    (Python planners always do); True insists on the compiled step for the whole batch (ValueError saying why
    it cannot). All give identical results. An empty batch raises UserInputError.
    """
    batch = scenarios if isinstance(scenarios, BatchParams) else pack(list(scenarios))
    if batch.size == 0:  # a packed batch cut to nothing (`take` with no index): as `pack([])` says
        raise UserInputError("a batch needs at least one scenario")
    check_budgets(batch, trace)
    planner_name = batch.planner_names[0] if planner is None else type(planner).__name__
    planner = planner if planner is not None else _planner_for(batch.planner_names)
    planner.reset(batch)
    mode_names = planner_mode_names(planner)
    if compiled is not False:
        why_not = compiled_support(batch, planner, channel, trace)
        if why_not is None:
            done = run_compiled(batch, planner, len(mode_names), trace)
            if done is not None:
                return BatchRun(batch, done[0], mode_names, done[2], done[1])
            planner.reset(batch)  # a variant changes mode too often to buffer its transitions: per step
        elif compiled:
            raise ValueError(f"simulate(compiled=True): no compiled step for this run ({why_not})")
        elif channel is None and not trace:
            split = _split_run(batch, planner, planner_name, mode_names)
            if split is not None:
                return split
    return _per_step(batch, planner, planner_name, mode_names, channel, trace)


def _per_step(
    batch: BatchParams,
    planner: Planner,
    planner_name: str,
    mode_names: tuple[str, ...],
    channel: Channel | None,
    trace: bool,
) -> BatchRun:
    """The per-step path: the batch in lock-step, the planner (reset for it) called from Python every step."""
    stepper = BatchStepper(batch, len(mode_names), channel)
    recorder = TraceRecorder(batch.n_steps) if trace else None
    can_compact = recorder is None and compactable(planner, stepper.channel, stepper.sensor)
    declared = isinstance(planner, PlannerBase)  # declares mode and warning: read them directly (a hot loop)
    for _ in range(batch.n_steps):
        observation = stepper.observe()
        work, active = stepper.work, stepper.active
        old_mode = planner.mode if declared else planner_mode(planner)
        old_mode = None if old_mode is None else old_mode.copy()
        command = checked_planner_command(planner.act(observation), stepper.params.size, planner_name)
        if old_mode is not None:
            work.record_modes(observation.t_s, active, old_mode, planner.mode if declared else planner_mode(planner))
        warning = planner.warning if declared else planner_warning(planner)
        if warning is not None:
            work.record_warning(observation.t_s, active, warning)
        door_hold = planner.door_hold if declared else planner_door_hold(planner)
        running = stepper.advance(command, door_hold).running
        if recorder is not None:
            recorder.add(stepper, planner, command)
        if running == 0:
            break
        if can_compact and running < COMPACT_BELOW * active.size:
            planner.compact(stepper.compact())
    recorded = None
    if recorder is not None:  # a run of no step: the columns without a row, as the compiled step gives them
        mode = planner_mode(planner)
        recorded = (
            recorder.finish()
            if recorder.rows
            else trace_columns(
                0,
                batch.size,
                batch.vru_slots,
                stepper.has_driver,
                stepper.has_door,
                np.int8 if mode is None else np.asarray(mode).dtype,
            )
        )
    return BatchRun(batch, stepper.finish(), mode_names, recorded, stepper.step_index)


def _split_run(batch: BatchParams, planner: Planner, planner_name: str, mode_names: tuple[str, ...]) -> BatchRun | None:
    """Run the variants with a driver or a door (`ego.driver`, `ego.door`) per step and the others with the
    compiled step, as two batches, and put their results together as the whole batch's; None when that does not
    apply (no such variants, only such variants, or the compiled step cannot run the others either) or the
    compiled part must run per step after all (`run_compiled`). A variant's results do not depend on the rest of
    its batch, and both paths give identical results, so this equals one per-step run of the batch (the
    transitions in the same order: by step, then by variant); it saves the per-step path's fixed cost per step
    for the variants that can do without it. The planner ends the run reset for the per-step variants."""
    low_speed = batch.driver.has | batch.door.has
    if low_speed.all() or not low_speed.any():
        return None
    fast_rows, slow_rows = np.flatnonzero(~low_speed), np.flatnonzero(low_speed)
    fast = take(batch, fast_rows)
    planner.reset(fast)
    if compiled_support(fast, planner, None, False) is not None:
        planner.reset(batch)
        return None
    done = run_compiled(fast, planner, len(mode_names))
    if done is None:
        planner.reset(batch)
        return None
    slow_batch = take(batch, slow_rows)
    planner.reset(slow_batch)
    slow = _per_step(slow_batch, planner, planner_name, mode_names, None, False)
    metrics = RunMetrics(batch, len(mode_names))
    metrics.merge_runs([(fast_rows, done[0]), (slow_rows, slow.metrics)])
    return BatchRun(batch, metrics, mode_names, None, max(done[1], slow.steps))


SENSOR_BYTES_PER_ROW = 1 + 6 * 8
"""A sensor ring-buffer row of one VRU: its visibility flag and its true kinematics (6 doubles)."""
QUEUE_BYTES_PER_SLOT = 8 + 8 + 6 * 8
"""A V2X queue slot of one VRU: generation and due steps, and the message's kinematics (6 doubles)."""


def delay_buffer_bytes(batch: BatchParams) -> int:
    """Memory of the batch's sensor latency ring buffer and V2X message queues, bytes (as the models allocate)."""
    rows = history_depth(batch.sensor, batch.n_steps)
    slots = queue_slots(batch.channel.queue_capacity, batch.n_steps)
    return batch.size * batch.vru_slots * (rows * SENSOR_BYTES_PER_ROW + slots * QUEUE_BYTES_PER_SLOT)


def check_budgets(batch: BatchParams, trace: bool) -> None:
    """Refuse a batch beyond the work budgets before it runs: its variant-steps, its sensor latency and V2X queue
    memory, and its trace's memory."""
    what = f"{batch.size:,} variants x {batch.n_steps:,} steps of one batch run"
    check_limit("batch_variant_steps", batch.size * batch.n_steps, what)
    delays = (
        f"sensor.latency_s and v2x.channel latency_s + jitter_s over sim.dt_s: {batch.size:,} variants x "
        f"{batch.vru_slots} VRUs x up to {batch.n_steps:,} steps held"
    )
    check_limit("delay_buffer_bytes", delay_buffer_bytes(batch), delays)
    if trace:
        check_trace_budget(batch.n_steps, batch.size, batch.vru_slots)
