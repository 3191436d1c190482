"""The compiled step: a whole run of a built-in planner in one compiled call, variant by variant.

`simulate` (vrusim.engine.simulate) steps the batch in lock-step and calls the planner from Python every step.
For the built-in planners `fsm`, `none`, `aeb` and `predictive` the same step exists compiled: one kernel runs
each variant's whole horizon (sensing, sensor model, RSU and channel, fusion, planner, VRU and ego motion,
contact, TTC, the streamed metrics and the stop rules) without returning to Python, variants spread over the
cores (threads: the kernels release the GIL). Each part is the very per-variant function the lock-step kernels
loop over (`*_variant`), called in the same order, so both paths give bit-identical results; a variant simply
stops at its own stop step instead of waiting to be compacted away. The kernels get most of their state laid
out variant by variant (`VARIANT_MAJOR`), the layout that suits running one variant at a time.

A trace is recorded inside the kernel, row by row (`_traced`). What the compiled step does not cover runs the
per-step path (`compiled_support` says why): a planner of another class (a subclass of a built-in too) or an
instance whose `act` was replaced, a channel passed in, drivers and doors (`ego.driver`, `ego.door`), VRU motion
models other than `point_mass`, and plug-in V2X loss models.
"""

from __future__ import annotations

from collections.abc import Sequence
from concurrent.futures import ThreadPoolExecutor

import numba
import numpy as np

from vrusim.engine.accumulators import (
    FIRST_WARNING,
    PREV_TTC,
    SURROGATE_START,
    TRAVEL,
    WARNING_TTC,
    RunMetrics,
    record_detection_variant,
    record_step_variant,
)
from vrusim.engine.stepper import checked_planner_command
from vrusim.engine.surrogates import surrogates_variant
from vrusim.engine.trace_recorder import trace_columns
from vrusim.geometry.contact import clearance_variant
from vrusim.geometry.ttc import ttc_variant
from vrusim.kernels import njit
from vrusim.planners import aeb
from vrusim.planners.aeb import AebPlanner, aeb_variant
from vrusim.planners.base import HoldSpeedPlanner, PlannerBase
from vrusim.planners.conflict import TRACK_SIZE
from vrusim.planners.fsm import FsmPlanner, fsm_variant
from vrusim.planners.predictive import PredictivePlanner, predictive_variant
from vrusim.sim.ego import ego_variant
from vrusim.sim.observation import fuse_variant
from vrusim.sim.params import BatchParams
from vrusim.sim.sensing.occlusion import occlude_variant
from vrusim.sim.sensing.registry import sensor_model_entry
from vrusim.sim.sensing.sector import perceived_variant
from vrusim.sim.sensing.sensor_model import BUILTIN_SENSOR_MODELS, observe_variant
from vrusim.sim.sensing.sensor_params import history_depth
from vrusim.sim.state import initial_ego, initial_vrus
from vrusim.sim.v2x.channel import RealisticChannel, make_channel
from vrusim.sim.v2x.kernels import channel_variant
from vrusim.sim.v2x.messages import coverage_variant
from vrusim.sim.vru.motion import point_mass_variant
from vrusim.sim.vru.point_mass import POINT_MASS

COMPILED_PLANNERS: dict[type, str] = {
    FsmPlanner: "fsm",
    HoldSpeedPlanner: "none",
    AebPlanner: "aeb",
    PredictivePlanner: "predictive",
}
"""Planner classes with a compiled step (exactly these classes: a subclass may change `act`)."""
_COMPILED_ACTS = {planner_class: planner_class.act for planner_class in COMPILED_PLANNERS}
"""Each class's own `act`, which its compiled step does: a class whose `act` was replaced since (a mock, a
wrapper for instrumentation) runs per step."""
TRANSITIONS_PER_VARIANT = 64
"""Mode transitions each variant has room for in a first compiled run; a run in which some variant made more
(an AEB chattering between warning and cruise makes 57 in the engine benchmark) counts them all and is run again
with room for the most any variant made."""
TRANSITION_BUFFER_BYTES = 256 * 2**20
"""Largest transition buffer a rerun may take (10 bytes a transition and variant); beyond it the batch runs per
step, which records transitions as they happen."""
_OK, _BAD_COMMAND = 0, 1


def compiled_support(batch: BatchParams, planner: object, channel: object, trace: bool) -> str | None:
    """Why this run needs the per-step path (a short reason), or None when the compiled step can run it."""
    if type(planner) not in COMPILED_PLANNERS:
        return f"planner {type(planner).__name__} has no compiled step"
    if "act" in getattr(planner, "__dict__", {}):
        return f"planner {type(planner).__name__}'s act is replaced on the instance"
    if type(planner).act is not _COMPILED_ACTS[type(planner)]:
        return f"planner {type(planner).__name__}'s act is replaced on the class"
    if channel is not None:
        return "a channel object was passed in"
    if batch.vru_motion != POINT_MASS:
        return f"VRU motion model {batch.vru_motion!r}"
    if batch.driver.has.any() or batch.door.has.any():
        return "drivers or doors (ego.driver, ego.door)"
    sensor_model = sensor_model_entry(batch).name
    if sensor_model not in BUILTIN_SENSOR_MODELS:  # a registered plug-in: runs per step
        return f"the plug-in sensor model {sensor_model!r}"
    made = make_channel(batch)
    if isinstance(made, RealisticChannel):
        made.reset(batch)
        if made.plugins:
            return "a plug-in V2X loss model"
    return None


# ---------------------------------------------------------------------------------------------------------------
# one step of one variant, split where the planner acts


@njit(cache=True, inline="always")
def _observe(b, step, world, sensor, v2x, vrus, ego, scratch, metrics):  # pragma: no cover (compiled)
    """Sensing, sensor model, RSU, channel, fusion and first detections of variant b at step `step`
    (`BatchStepper.observe`)."""
    dt = world[0]
    t = step * dt
    enabled, range_m, cos_half, sin_half, has_obstacles, count, ox, oy, ohx, ohy, ohl, ohw = sensor[:12]
    realistic_sensor, seed, latency, period, probability, pos_sigma, vel_sigma, seen, history, held, held_est = sensor[
        12:
    ]
    kin, radius = vrus[17], vrus[12]
    hx, hy, front_x, front_y, centre_x, centre_y = ego[2], ego[3], ego[10], ego[11], ego[12], ego[13]
    visible, sensed, sensed_kin, sensor_age, sent, covered, link, received, msg_kin, msg_age = scratch[:10]
    detected, source, estimate, zeros = scratch[10], scratch[11], scratch[12], scratch[20]
    perceived_variant(
        b, front_x, front_y, hx, hy, range_m, cos_half, sin_half, enabled, kin[0], kin[1], radius, visible
    )
    if has_obstacles:
        occlude_variant(b, front_x, front_y, kin[0], kin[1], radius, count, ox, oy, ohx, ohy, ohl, ohw, visible)
    if realistic_sensor:
        observe_variant(
            b, step, visible, kin, seed, latency, period, probability, pos_sigma, vel_sigma, seen, history, held,
            held_est, sensed, sensed_kin,
        )  # fmt: skip
        since = max(step - latency[b], 0)
        sensor_age[b] = (step - (since // period[b]) * period[b]) * dt
    v2x_enabled, rsu_x, rsu_y, comm, coverage, valid, realistic_channel = v2x[:7]
    coverage_variant(
        b, v2x_enabled, rsu_x, rsu_y, comm, coverage, valid, centre_x, centre_y, kin[0], kin[1], sent, covered, link,
        realistic_channel,
    )  # fmt: skip
    if realistic_channel:
        settings, state = v2x[7:]
        n = int(np.floor(t / dt + 0.5))  # round(t / dt), as the channel object computes it
        channel_variant(b, n, dt, settings, state, covered, sent, kin, link, received, msg_kin, msg_age)
        got, got_kin, got_age = received, msg_kin, msg_age
    else:
        got, got_kin, got_age = sent, kin, zeros
    if realistic_sensor:
        fuse_variant(b, sensed, sensed_kin, sensor_age, got, got_kin, got_age, detected, source, estimate)
        record_detection_variant(b, t, scratch[19], sensed, got, metrics[0])
    else:
        fuse_variant(b, visible, kin, sensor_age, got, got_kin, got_age, detected, source, estimate)
        record_detection_variant(b, t, scratch[19], visible, got, metrics[0])


@njit(cache=True, inline="always")
def _mode_changed(b, step, old, new, metrics):  # pragma: no cover (compiled)
    """Record a planner mode transition of variant b at step `step` (`RunMetrics.record_modes`); one beyond the
    variant's room is counted, not stored (the run is then repeated with more room)."""
    first_mode, steps, olds, news, counts = metrics[4], metrics[5], metrics[6], metrics[7], metrics[8]
    if old == new:
        return
    i = counts[b]
    if i < steps.shape[1]:
        steps[b, i], olds[b, i], news[b, i] = step, old, new
    counts[b] = i + 1
    if np.isnan(first_mode[b, new]):
        first_mode[b, new] = step * metrics[10]


@njit(cache=True, inline="always")
def _advance(b, step, world, vrus, ego, scratch, metrics):  # pragma: no cover (compiled)
    """VRU and ego motion under `scratch` command, contact, TTC, streamed metrics and stop rules of variant b
    (`BatchStepper.advance`); return whether it still runs."""
    dt, n_steps, duration, stop_on_collision, stop_at_route_end, path, offsets = world[:7]
    k_lat, k_head, max_kappa, max_accel, max_decel, lag, max_jerk, rear_to_front, rear_to_centre = world[7:16]
    half_length, half_width, route_length, threshold = world[16:20]
    vru_path, vru_offset, kind, value, px, py, top, vru_accel, tau, initial, brake_after, brake_decel = vrus[:12]
    radius, started, started_at, vru_station, vru_speed, kin, stopped_at = vrus[12:]
    x, y, hx, hy, speed, accel, actuator, station, curvature, lateral = ego[:10]
    front_x, front_y, centre_x, centre_y = ego[10:]
    contact, ttc, moving, command, door_hit, active = (
        scratch[13],
        scratch[14],
        scratch[15],
        scratch[16],
        scratch[18],
        scratch[19],
    )
    values, collided = metrics[0], metrics[3]
    t = step * dt
    moving[b] = speed[b] > 0.0
    point_mass_variant(
        b, vru_path, vru_offset, kind, value, px, py, top, vru_accel, tau, initial, brake_after, brake_decel, dt,
        t, front_x, front_y, speed, station, started, started_at, vru_station, vru_speed, kin, stopped_at,
    )  # fmt: skip
    ego_variant(
        b, path, offsets, k_lat, k_head, max_kappa, max_accel, max_decel, lag, max_jerk, dt, command, x, y, hx, hy,
        speed, accel, actuator, station, curvature, lateral, rear_to_front, rear_to_centre, front_x, front_y,
        centre_x, centre_y,
    )  # fmt: skip
    t_next = (step + 1) * dt
    clearance_variant(b, centre_x, centre_y, hx, hy, half_length, half_width, kin[0], kin[1], radius, contact)
    ttc_variant(
        b, centre_x, centre_y, hx, hy, half_length, half_width, speed, kin[0], kin[1], radius, kin[2], kin[3], ttc
    )
    record_step_variant(
        b, t_next, dt, active, speed, accel, actuator, curvature, station, hx, hy, moving, route_length,
        contact[0], contact[1], contact[2], ttc, kin, centre_x, centre_y, half_length, half_width, radius, door_hit,
        values, collided,
    )  # fmt: skip
    surrogates_variant(
        b, t_next, dt, active, speed, hx, hy, centre_x, centre_y, station, rear_to_centre, half_length, half_width,
        radius, kin, contact[0], ttc, threshold, metrics[1], metrics[2],
    )  # fmt: skip
    if (stop_on_collision[b] and collided[b]) or (stop_at_route_end[b] and values[TRAVEL, b] >= 0.0):
        stop = True
    else:
        stop = step + 1 >= n_steps or not t_next < duration[b] - 1e-9
    return not stop


@njit(cache=True, inline="always")
def _ego_of(ego_rows):  # pragma: no cover (compiled)
    """The ego's 14 state arrays (`EgoState`, in `_run_once`'s order) from the rows of one array [14, B]: views
    taken inside the kernel, which all lie at one address plus constants when the array is variant-major."""
    E = ego_rows
    return (E[0], E[1], E[2], E[3], E[4], E[5], E[6], E[7], E[8], E[9], E[10], E[11], E[12], E[13])


@njit(cache=True, inline="always")
def _world_of(world_rows):  # pragma: no cover (compiled)
    """The run's settings in the order `_advance` unpacks them, its 15 float settings from the rows of one array
    [15, B] (`_ego_of`)."""
    dt, n_steps, stop_on_collision, stop_at_route_end, path, offsets, W = world_rows
    return (
        dt, n_steps, W[0], stop_on_collision, stop_at_route_end, path, offsets, W[1], W[2], W[3], W[4], W[5], W[6],
        W[7], W[8], W[9], W[10], W[11], W[12], W[13], W[14],
    )  # fmt: skip


@njit(cache=True, inline="always")
def _finish(b, step, status, scratch, metrics):  # pragma: no cover (compiled)
    """Variant b stopped after `step` steps (or could not go on: `status`); its step count is that of its first
    stop (in a traced batch a stopped variant goes on moving: `_traced`)."""
    if scratch[19][b]:
        metrics[9][b] = step
    scratch[19][b] = False
    metrics[11][b] = status


@njit(cache=True, inline="always")
def _traced(b, step, running, trace, world, v2x, vrus, ego, scratch, metrics):  # pragma: no cover (compiled)
    """After step `step` of a traced run: write variant b's row, finish it at its own stop, and return whether its
    loop goes on. As on the per-step path, whose traced batches are never compacted, a stopped variant goes on
    moving, inactive (no results, no transitions), until the batch's last step `trace[2]` (0: stop with it)."""
    _trace_row(b, step, trace, world, v2x, vrus, ego, scratch)
    if not running and scratch[19][b]:
        _finish(b, step + 1, _OK, scratch, metrics)
    return scratch[19][b] or step + 1 < trace[2]


@njit(cache=True, inline="always")
def _trace_row(b, step, trace, world, v2x, vrus, ego, scratch):  # pragma: no cover (compiled)
    """Write row `step` of variant b's trace (`TraceRecorder.add`, the columns `trace[0]` in `TRACE_COLUMNS`'
    order): the state after the step, and the detections, V2X ages and planner mode (`trace[1]`, the planner's
    mode array, which the kernel updates) of its start."""
    (
        t_s, ego_x, ego_y, heading_x, heading_y, speed, accel, command, curvature, station, mode,
        vru_x, vru_y, vru_speed, detected, source, v2x_age, clearance, ttc,
    ) = trace[0]  # fmt: skip
    planner_mode = trace[1]
    t_s[step] = (step + 1) * world[0]
    ego_x[step, b], ego_y[step, b] = ego[12][b], ego[13][b]
    heading_x[step, b], heading_y[step, b] = ego[2][b], ego[3][b]
    speed[step, b], accel[step, b], command[step, b] = ego[4][b], ego[5][b], scratch[16][b]
    curvature[step, b], station[step, b], mode[step, b] = ego[8][b], ego[7][b], planner_mode[b]
    kin, received, age = vrus[17], scratch[4], scratch[20]  # the ideal channel: what was sent, at age 0
    if v2x[6]:
        received, age = scratch[7], scratch[9]
    for k in range(kin.shape[2]):
        vru_x[step, b, k], vru_y[step, b, k], vru_speed[step, b, k] = kin[0, b, k], kin[1, b, k], vrus[16][b, k]
        detected[step, b, k], source[step, b, k] = scratch[10][b, k], scratch[11][b, k]
        v2x_age[step, b, k] = age[b, k] if received[b, k] else np.nan
    clearance[step, b], ttc[step, b] = slots_minimum(scratch[13][0], b), slots_minimum(scratch[14], b)


@njit(cache=True, inline="always")
def slots_minimum(values, b):  # pragma: no cover (compiled)
    """The smallest of variant b's values over the VRU slots (`values` [B, K]) as NumPy's `.min(axis=1)` takes it,
    which the per-step recorder uses: NaN if any is NaN, and of equal values (0.0 and -0.0) the later. (Python's
    `min` skips a NaN after the first slot and keeps the first of equal values.)"""
    smallest = values[b, 0]
    for k in range(1, values.shape[1]):
        value = values[b, k]
        if not (smallest < value or np.isnan(smallest)):  # np.minimum's rule
            smallest = value
    return smallest


# ---------------------------------------------------------------------------------------------------------------
# one kernel per planner: the planner's step between `_observe` and `_advance`


@njit(cache=True, nogil=True, _nrt=False)
def _run_fsm(
    first, stop, world_rows, sensor, v2x, vrus, ego_rows, scratch, metrics, plan, trace
):  # pragma: no cover (compiled)
    world, ego = _world_of(world_rows), _ego_of(ego_rows)
    table, tracks, station, mode, zone_length, ego_length = plan
    dt, n_steps, path, offsets, rear_to_front, half_width = world[0], world[1], world[5], world[6], world[14], world[17]
    cruise = world[20]
    detected, estimate, command, front_station = scratch[10], scratch[12], scratch[16], scratch[17]
    radius, ego_station, speed = vrus[12], ego[7], ego[4]
    for b in range(first, stop):
        for step in range(n_steps):
            _observe(b, step, world, sensor, v2x, vrus, ego, scratch, metrics)
            old = mode[b]
            front_station[b] = ego_station[b] + rear_to_front[b]
            fsm_variant(
                b, path, offsets, step * dt, front_station, speed, cruise, half_width, zone_length, ego_length,
                detected, estimate, radius, table, tracks, station, mode, command,
            )  # fmt: skip
            if not np.isfinite(command[b]):
                _finish(b, step, _BAD_COMMAND, scratch, metrics)
                break
            if trace is None or scratch[19][b]:  # a stopped variant of a traced batch records none
                _mode_changed(b, step, old, mode[b], metrics)
            running = _advance(b, step, world, vrus, ego, scratch, metrics)
            if trace is not None:
                running = _traced(b, step, running, trace, world, v2x, vrus, ego, scratch, metrics)
            if not running:
                _finish(b, step + 1, _OK, scratch, metrics)
                break


@njit(cache=True, nogil=True, _nrt=False)
def _run_none(
    first, stop, world_rows, sensor, v2x, vrus, ego_rows, scratch, metrics, plan, trace
):  # pragma: no cover (compiled)
    world, ego = _world_of(world_rows), _ego_of(ego_rows)
    n_steps, command = world[1], scratch[16]
    for b in range(first, stop):
        for step in range(n_steps):
            _observe(b, step, world, sensor, v2x, vrus, ego, scratch, metrics)
            command[b] = 0.0  # HoldSpeedPlanner without a driver
            running = _advance(b, step, world, vrus, ego, scratch, metrics)
            if trace is not None:
                running = _traced(b, step, running, trace, world, v2x, vrus, ego, scratch, metrics)
            if not running:
                _finish(b, step + 1, _OK, scratch, metrics)
                break


@njit(cache=True, nogil=True, _nrt=False)
def _run_aeb(
    first, stop, world_rows, sensor, v2x, vrus, ego_rows, scratch, metrics, plan, trace
):  # pragma: no cover (compiled)
    world, ego = _world_of(world_rows), _ego_of(ego_rows)
    table, tracks, mode, ttc_out, half_length, rear_to_centre, has_driver, driver_accel = plan
    dt, n_steps, path, offsets, half_width, cruise = world[0], world[1], world[5], world[6], world[17], world[20]
    detected, estimate, command = scratch[10], scratch[12], scratch[16]
    radius, ego_station, speed, values = vrus[12], ego[7], ego[4], metrics[0]
    for b in range(first, stop):
        for step in range(n_steps):
            _observe(b, step, world, sensor, v2x, vrus, ego, scratch, metrics)
            old = mode[b]
            aeb_variant(
                b, path, offsets, step * dt, ego_station, rear_to_centre, speed, cruise, half_length, half_width,
                detected, estimate, radius, table, tracks, mode, ttc_out, has_driver, driver_accel, command,
            )  # fmt: skip
            if not np.isfinite(command[b]):
                _finish(b, step, _BAD_COMMAND, scratch, metrics)
                break
            if trace is None or scratch[19][b]:  # a stopped variant of a traced batch records none
                _mode_changed(b, step, old, mode[b], metrics)
            warned = mode[b] >= aeb.WARNING and (trace is None or scratch[19][b])
            if warned and np.isnan(values[FIRST_WARNING, b]):  # RunMetrics.record_warning
                values[FIRST_WARNING, b] = step * dt
                values[WARNING_TTC, b] = values[PREV_TTC, b]
            running = _advance(b, step, world, vrus, ego, scratch, metrics)
            if trace is not None:
                running = _traced(b, step, running, trace, world, v2x, vrus, ego, scratch, metrics)
            if not running:
                _finish(b, step + 1, _OK, scratch, metrics)
                break


@njit(cache=True, nogil=True, _nrt=False)
def _run_predictive(
    first, stop, world_rows, sensor, v2x, vrus, ego_rows, scratch, metrics, plan, trace
):  # pragma: no cover (compiled)
    world, ego = _world_of(world_rows), _ego_of(ego_rows)
    (
        table, kind, tracks, station, path_station, yielding, mode, required, last_plan, own_command, bounds,
        vru_paths, vru_offsets, rear_to_centre, ego_length, front_x, front_y,
    ) = plan  # fmt: skip
    dt, n_steps, path, offsets, rear_to_front, half_width = world[0], world[1], world[5], world[6], world[14], world[17]
    cruise = world[20]
    detected, estimate, command, front_station = scratch[10], scratch[12], scratch[16], scratch[17]
    radius, x, y, hx, hy, ego_station, speed = vrus[12], ego[0], ego[1], ego[2], ego[3], ego[7], ego[4]
    for b in range(first, stop):
        for step in range(n_steps):
            _observe(b, step, world, sensor, v2x, vrus, ego, scratch, metrics)
            old = mode[b]
            front_x[b] = x[b] + rear_to_front[b] * hx[b]
            front_y[b] = y[b] + rear_to_front[b] * hy[b]
            front_station[b] = ego_station[b] + rear_to_front[b]
            predictive_variant(
                b, path, offsets, step * dt, dt, front_x, front_y, front_station, rear_to_front, rear_to_centre,
                speed, cruise, half_width, ego_length, detected, estimate, radius, vru_paths, vru_offsets, kind,
                table, tracks, station, path_station, yielding, mode, required, last_plan, own_command, bounds,
            )  # fmt: skip
            command[b] = own_command[b]
            if not np.isfinite(command[b]):
                _finish(b, step, _BAD_COMMAND, scratch, metrics)
                break
            if trace is None or scratch[19][b]:  # a stopped variant of a traced batch records none
                _mode_changed(b, step, old, mode[b], metrics)
            running = _advance(b, step, world, vrus, ego, scratch, metrics)
            if trace is not None:
                running = _traced(b, step, running, trace, world, v2x, vrus, ego, scratch, metrics)
            if not running:
                _finish(b, step + 1, _OK, scratch, metrics)
                break


_KERNELS = {"fsm": _run_fsm, "none": _run_none, "aeb": _run_aeb, "predictive": _run_predictive}


# ---------------------------------------------------------------------------------------------------------------
# packing the batch into the kernels' tuples


def _c(array) -> np.ndarray:
    return np.ascontiguousarray(array)


VARIANT_MAJOR = {"fsm": True, "none": True, "aeb": True, "predictive": False}
"""Whether a planner's kernel gets its multi-field arrays [fields, B, ...] (the accumulators, the VRUs' kinematics,
the step's vector scratch, the ego's state, the run's float settings) laid out variant by variant (Fortran
order) instead of field by field.

The kernels run one variant's whole horizon at a time. Field by field, every row of such an array (and every
separate array) has an address of its own, which the kernel keeps reloading; variant by variant, a variant's
fields lie at one address plus constants. Measured (one thread, B = 2,000): 14-17 % off a step for the FSM and
`none` kernels, 7 % for the AEB; the predictive kernel, whose time is in its occupancy prediction, ran 3-50 %
slower (docs/architecture.md). Bit-identical either way."""


def _state_array(
    fields: tuple[int, ...], size: int, slots: int | None, variant_major: bool, fill: float = 0.0
) -> np.ndarray:
    """A new array [*fields, B] or [*fields, B, K] filled with `fill`.

    Variant-major, it has room for at least 2 variants (the kernel reads the first `size`): one variant's array is
    C-ordered as well, which numba would type as such and compile a second version of the kernel for.
    """
    shape = (*fields, max(size, 2) if variant_major else size, *(() if slots is None else (slots,)))
    return np.full(shape, fill, order="F" if variant_major else "C")


def _stacked(rows: Sequence[np.ndarray] | np.ndarray, variant_major: bool) -> np.ndarray:
    """The arrays `rows` (each [B] or [B, K]) as the rows of one `_state_array`."""
    first = rows[0]
    stacked = _state_array((len(rows),), first.shape[0], first.shape[1] if first.ndim == 2 else None, variant_major)
    for row, array in enumerate(rows):
        stacked[row, : first.shape[0]] = array
    return stacked


def _state_copy(array: np.ndarray, variant_major: bool) -> np.ndarray:
    """`array` [fields, B, ...] as a variant-major `_state_array` (a copy), or itself when not variant-major."""
    return _stacked(array, True) if variant_major else array


def _new_tracks(size: int, slots: int) -> tuple[np.ndarray, np.ndarray]:
    """`conflict.new_tracks` without an observation."""
    tracks = np.zeros((size, slots, TRACK_SIZE))
    tracks[..., 0] = -np.inf
    return tracks, np.zeros((size, slots))


def _planner_state(name: str, planner: PlannerBase, batch: BatchParams) -> tuple:
    """The reset planner's per-variant state, in the order its kernel unpacks it."""
    size, slots = batch.size, batch.vru_slots
    if name == "fsm":
        assert isinstance(planner, FsmPlanner)
        planner.tracks, planner.station = _new_tracks(size, slots)
        ego_length = 2.0 * batch.half_length_m
        return (_c(planner.table), planner.tracks, planner.station, planner.mode, _c(planner.zone_length), ego_length)
    if name == "aeb":
        assert isinstance(planner, AebPlanner)
        planner.tracks, _ = _new_tracks(size, slots)
        return (
            _c(planner.table), planner.tracks, planner.mode, planner.ttc_s, _c(planner.half_length),
            _c(planner.rear_to_centre), np.zeros(size, dtype=bool), np.zeros(size),
        )  # fmt: skip
    if name == "predictive":
        assert isinstance(planner, PredictivePlanner)
        planner.tracks, planner.station = _new_tracks(size, slots)
        return (
            _c(planner.table), _c(planner.kind), planner.tracks, planner.station, planner.path_station,
            planner.yielding, planner.mode, planner.required_decel_mps2, planner.plan, planner.command,
            np.empty((size, 5)), planner.vru_paths, _c(planner.vru_path_offset), _c(planner.rear_to_centre),
            _c(planner.ego_length), np.empty(size), np.empty(size),
        )  # fmt: skip
    return (np.zeros(1),)


def _sensor_tuple(batch: BatchParams) -> tuple:
    """Sector, obstacles and (realistic) sensor model settings and state."""
    obstacles = batch.obstacles
    sensor = batch.sensor
    realistic = not bool(sensor.ideal.all())
    shape = batch.vru_valid.shape
    depth = history_depth(sensor, batch.n_steps) if realistic else 1
    return (
        _c(batch.sensor_enabled), _c(batch.sensor_range_m), _c(batch.sensor_cos_half), _c(batch.sensor_sin_half),
        bool(obstacles.x_m.shape[1]), *(_c(a) for a in obstacles), realistic, _c(batch.seed),
        _c(sensor.latency_steps), _c(sensor.frame_steps), _c(sensor.detection_probability),
        _c(sensor.position_sigma_m), _c(sensor.velocity_sigma_mps), np.zeros((depth, *shape), dtype=bool),
        np.zeros((depth, 6, *shape)), np.zeros(shape, dtype=bool), np.zeros((6, *shape)),
    )  # fmt: skip


def _v2x_tuple(batch: BatchParams) -> tuple:
    """RSU settings and the channel's settings and state (a fresh `RealisticChannel`'s, unused when ideal)."""
    channel = RealisticChannel()
    channel.reset(batch)
    realistic = isinstance(make_channel(batch), RealisticChannel)
    return (
        _c(batch.v2x_enabled), _c(batch.rsu_x_m), _c(batch.rsu_y_m), _c(batch.comm_range_m),
        _c(batch.coverage_range_m), _c(batch.vru_valid), realistic,
        (
            channel.seed, channel.mode, channel.loss_model, _c(channel.cfg), _c(channel.loss_params),
            _c(channel.outage_start), _c(channel.outage_end), channel.outage_count,
        ),
        (
            channel.last_gen, channel.due, channel.force, channel.ref, channel.was_covered, channel.link_state,
            channel.buf_gen, channel.buf_due, channel.buf_kin, channel.buf_head, channel.buf_count,
            channel.message_step, channel.track_kin, channel.generated, channel.delivered,
            np.zeros((1, 1), dtype=bool),
        ),
    )  # fmt: skip


def run_compiled(
    batch: BatchParams, planner: PlannerBase, mode_count: int, trace: bool = False
) -> tuple[RunMetrics, int, dict[str, np.ndarray] | None] | None:
    """Run the batch with the planner's compiled step (the planner already reset): its metrics (`mode_count`
    planner modes), the number of steps the batch took and, with `trace`, its per-step trace
    (`TraceRecorder.finish`'s columns; a batch of several variants is run first without it, for its last step).
    A run in which some variant changed mode more often than `TRANSITIONS_PER_VARIANT` is run again with room for
    all of them; None (run it per step) when that room would exceed `TRANSITION_BUFFER_BYTES`. A non-finite
    command is reported like the per-step path does.
    """
    until = 0
    if trace and batch.size > 1:  # the batch's last step, until which its stopped variants go on moving
        untraced = run_compiled(batch, planner, mode_count)
        if untraced is None:
            return None
        until = untraced[1]
        planner.reset(batch)
    capacity = TRANSITIONS_PER_VARIANT
    while True:
        metrics = RunMetrics(batch, mode_count)
        columns = trace_columns(batch.n_steps, batch.size, batch.vru_slots) if trace else None
        steps, needed = _run_once(batch, planner, metrics, capacity, columns, until)
        if needed <= capacity:
            recorded = None if columns is None else {name: column[:steps] for name, column in columns.items()}
            return metrics, steps, recorded
        if needed * batch.size * TRANSITION_BYTES > TRANSITION_BUFFER_BYTES:
            return None
        planner.reset(batch)
        capacity = needed


TRANSITION_BYTES = 10
"""Bytes of one recorded transition: step (int64), old and new mode (int8)."""


def _run_once(
    batch: BatchParams,
    planner: PlannerBase,
    metrics: RunMetrics,
    capacity: int,
    trace: dict[str, np.ndarray] | None = None,
    until: int = 0,
) -> tuple[int, int]:
    """One compiled run with room for `capacity` transitions a variant, filling `metrics` (and the `trace`
    columns, when given, in which stopped variants go on moving until step `until`): (steps the batch took, the
    most transitions a variant made); the transitions are in `metrics` only when they all fitted."""
    name = COMPILED_PLANNERS[type(planner)]
    variant_major = VARIANT_MAJOR[name]
    size, slots = batch.size, batch.vru_slots
    shape = (size, slots)
    ego, vrus = initial_ego(batch), initial_vrus(batch)
    world_floats = (
        batch.duration_s, batch.lateral_gain, batch.heading_gain, batch.max_curvature_per_m, batch.max_accel_mps2,
        batch.max_decel_mps2, batch.lag_s, batch.max_jerk_mps3, batch.rear_to_front_m, batch.rear_to_centre_m,
        batch.half_length_m, batch.half_width_m, batch.route_length_m, batch.tet_ttc_threshold_s,
        batch.cruise_speed_mps,
    )  # fmt: skip
    world = (
        batch.dt_s, batch.n_steps, _c(batch.stop_on_collision), _c(batch.stop_at_route_end), batch.routes.arrays,
        _c(batch.route_offset), _stacked(world_floats, variant_major),
    )  # fmt: skip
    vru_tuple = (
        batch.vru_paths.arrays, _c(batch.vru_path_offset), _c(batch.trigger_kind), _c(batch.trigger_value),
        _c(batch.trigger_x_m), _c(batch.trigger_y_m), _c(batch.vru_top_speed_mps), _c(batch.vru_max_accel_mps2),
        _c(batch.vru_tau_s), _c(batch.vru_initial_speed_mps), _c(batch.vru_brake_after_s),
        _c(batch.vru_brake_decel_mps2), _c(batch.vru_radius_m), vrus.started, vrus.started_at_s, vrus.station_m,
        vrus.speed_mps, _state_copy(vrus.kinematics, variant_major), vrus.ego_stopped_at_s,
    )  # fmt: skip
    ego_tuple = (
        ego.x_m, ego.y_m, ego.heading_x, ego.heading_y, ego.speed_mps, ego.accel_mps2, ego.actuator_mps2,
        ego.station_m, ego.curvature_per_m, ego.lateral_error_m, ego.front_x_m, ego.front_y_m, ego.centre_x_m,
        ego.centre_y_m,
    )  # fmt: skip
    ego_rows = _stacked(ego_tuple, variant_major)
    scratch = (
        np.zeros(shape, dtype=bool), np.zeros(shape, dtype=bool), _state_array((6,), size, slots, variant_major),
        np.zeros(size), np.zeros(shape, dtype=bool), np.zeros(shape, dtype=bool), np.zeros(size),
        np.zeros(shape, dtype=bool), _state_array((6,), size, slots, variant_major), np.zeros(shape),
        np.zeros(shape, dtype=bool), np.zeros(shape, dtype=np.int8), _state_array((7,), size, slots, variant_major),
        _state_array((3,), size, slots, variant_major, np.inf), np.full(shape, np.inf), np.zeros(size, dtype=bool),
        np.zeros(size), np.zeros(size), np.zeros(shape, dtype=bool), np.ones(size, dtype=bool), np.zeros(shape),
    )  # fmt: skip
    steps_run, status = np.zeros(size, dtype=np.int64), np.zeros(size, dtype=np.int8)
    # the accumulator and the surrogate rows: copies when variant-major, written back after the run
    values = _state_copy(metrics.values[:SURROGATE_START], variant_major)
    surrogates = _state_copy(metrics.values[SURROGATE_START:], variant_major)
    metrics_tuple = (
        values, surrogates, metrics._per_vru, metrics.collided, metrics.first_mode_s,
        np.zeros((size, capacity), dtype=np.int64), np.zeros((size, capacity), dtype=np.int8),
        np.zeros((size, capacity), dtype=np.int8), np.zeros(size, dtype=np.int64), steps_run, batch.dt_s, status,
    )  # fmt: skip
    plan = _planner_state(name, planner, batch)
    traced = None if trace is None else (tuple(trace.values()), planner.mode, until)
    arguments = (
        world, _sensor_tuple(batch), _v2x_tuple(batch), vru_tuple, ego_rows, scratch, metrics_tuple, plan, traced
    )  # fmt: skip
    _over_threads(_KERNELS[name], size, arguments)
    if variant_major:
        metrics.values[:SURROGATE_START], metrics.values[SURROGATE_START:] = values[:, :size], surrogates[:, :size]
    if (status == _BAD_COMMAND).any():
        checked_planner_command(scratch[16], size, type(planner).__name__)  # raises the per-step path's error
    needed = int(metrics_tuple[8].max()) if size else 0
    if needed <= capacity:
        _collect_transitions(metrics, batch.dt_s, metrics_tuple[5:9])
    return (int(steps_run.max()) if size else 0), needed


CHUNKS_PER_THREAD = 8
"""Variants are run in this many chunks per thread, taken in turn, so that variants stopping early balance out."""
MIN_CHUNK = 64
"""Fewest variants per chunk (a chunk costs a few microseconds to start)."""


def chunk_order(size: int, threads: int) -> list[tuple[int, int]]:
    """The chunks `(first, stop)` of `size` variants in the order `threads` threads take them: in turn from
    `threads` equal runs of consecutive chunks, so that chunks running at the same time lie far apart in memory.
    (Taken in plain order, the threads worked on variants one chunk apart, and a batch of 2,500 ran 4–6 % slower
    on two threads.)"""
    chunk = max(MIN_CHUNK, -(-size // (threads * CHUNKS_PER_THREAD)))
    bounds = [(first, min(first + chunk, size)) for first in range(0, size, chunk)]
    runs = [bounds[len(bounds) * run // threads : len(bounds) * (run + 1) // threads] for run in range(threads)]
    return [run[taken] for taken in range(max(map(len, runs))) for run in runs if taken < len(run)]


def _over_threads(kernel, size: int, arguments: tuple) -> None:
    """Run `kernel(first, stop, *arguments)` over chunks of the variants (`chunk_order`) on numba's thread count
    (the kernels release the GIL); one thread runs it whole."""
    threads = numba.get_num_threads()
    bounds = chunk_order(size, threads)
    if threads == 1 or len(bounds) == 1:
        kernel(0, size, *arguments)
        return
    with ThreadPoolExecutor(threads) as pool:
        for done in [pool.submit(kernel, first, stop, *arguments) for first, stop in bounds]:
            done.result()


def _collect_transitions(metrics: RunMetrics, dt_s: float, buffers: tuple) -> None:
    """Append the recorded transitions in the per-step path's order: by step, then by variant."""
    steps, olds, news, counts = buffers
    rows = np.repeat(np.arange(counts.size), counts)
    slots = np.arange(rows.size) - np.repeat(np.cumsum(counts) - counts, counts)
    order = np.lexsort((rows, steps[rows, slots]))
    rows, slots = rows[order], slots[order]
    times = (steps[rows, slots] * dt_s).tolist()  # each step made a float and multiplied: Python's step * dt_s
    metrics.transitions.extend(
        zip(times, metrics._variant[rows].tolist(), olds[rows, slots].tolist(), news[rows, slots].tolist(), strict=True)
    )
