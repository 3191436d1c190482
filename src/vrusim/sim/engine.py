"""The batch engine: advances B variants in lock-step with a fixed time step.

Each step, from the state at time t: sensing (sector, occlusion → sensor model) → V2X (RSU → channel) → fused
observation → planner →
VRU triggers (judged on the ego state at t) and VRU motion to t + dt → ego motion to t + dt → contact check and
streaming metrics. A variant stops contributing to
its metrics when it collides (if `stop_on_collision`), completes its route (if `stop_at_route_end`) or reaches
its duration; the loop ends when every variant has stopped.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numba import njit

from vrusim.errors import UserInputError
from vrusim.metrics.streaming import RunMetrics
from vrusim.metrics.ttc import ttc_batch
from vrusim.planners.base import Planner
from vrusim.planners.registry import make_planner
from vrusim.scenario.schema import Scenario
from vrusim.sim.batch import BatchParams, pack
from vrusim.sim.compaction import compactable, take_ego, take_params, take_vrus
from vrusim.sim.contact import clearance_batch
from vrusim.sim.ego_dynamics import advance_egos
from vrusim.sim.observation import Observation, fuse
from vrusim.sim.sensing import sense
from vrusim.sim.sensor_model import make_sensor_model
from vrusim.sim.state import EgoState, initial_ego, initial_vrus
from vrusim.sim.v2x import Channel, make_channel, rsu_broadcast
from vrusim.sim.vru_motion import advance_vrus


@dataclass
class BatchRun:
    """Everything a batch run produced: parameters, streamed metrics, planner mode names, optional trace."""

    params: BatchParams
    metrics: RunMetrics
    mode_names: tuple[str, ...]
    trace: dict[str, np.ndarray] | None = None
    steps: int = 0


def _planner_for(scenarios: Sequence[Scenario]) -> Planner:
    names = {s.planner.name for s in scenarios}
    if len(names) != 1:
        raise UserInputError(f"planner.name: one batch runs one planner, got {sorted(names)}")
    return make_planner(names.pop())


COMPACT_BELOW = 0.8
"""Drop stopped variants from the working set once fewer than this fraction of it are still running."""


@dataclass
class _Scratch:
    """Per working set: read-only views of the state the planner observes, and reused step buffers."""

    ego_view: list[np.ndarray]
    route_offset: np.ndarray
    radius: np.ndarray
    fresh: np.ndarray
    """Age of an ideal sensor's reports, s (0)."""
    contact: np.ndarray
    """Clearance, outline x, outline y [3, B, K]."""
    ttc: np.ndarray


def _scratch(params: BatchParams, ego: EgoState) -> _Scratch:
    # kernels update the state arrays in place, views follow
    ego_view = [
        _read_only(a)
        for a in (ego.x_m, ego.y_m, ego.heading_x, ego.heading_y, ego.speed_mps, ego.accel_mps2, ego.station_m)
    ] + [_read_only(a) for a in (params.cruise_speed_mps, params.rear_to_front_m, params.half_width_m)]
    shape = params.vru_valid.shape
    return _Scratch(
        ego_view,
        _read_only(params.route_offset),
        _read_only(params.vru_radius_m),
        np.zeros(params.size),
        np.empty((3, *shape)),
        np.empty(shape),
    )


def simulate(
    scenarios: Sequence[Scenario] | BatchParams,
    planner: Planner | None = None,
    channel: Channel | None = None,
    trace: bool = False,
) -> BatchRun:
    """Run scenarios (or an already packed batch) as one batch; return the streamed results and optional trace.

    Without a trace, variants that have stopped are dropped from the working set as the run goes on (if the
    planner, channel and sensor model all have a `compact` method); their results are final by then. A
    planner or channel passed in then ends the run holding only the variants still running at its end.
    """
    batch = scenarios if isinstance(scenarios, BatchParams) else pack(list(scenarios))
    params = batch
    planner_name = params.scenarios[0].planner.name if planner is None else type(planner).__name__
    planner = planner if planner is not None else _planner_for(params.scenarios)
    channel = channel if channel is not None else make_channel(params)
    sensor = make_sensor_model(params)
    planner.reset(params)
    channel.reset(params)
    sensor.reset(params)
    mode_names = tuple(getattr(planner, "mode_names", ("running",)))
    metrics = RunMetrics(params, len(mode_names))
    work = metrics  # the metrics of the working set
    ego = initial_ego(params)
    vrus = initial_vrus(params)
    active = np.ones(params.size, dtype=bool)
    dt = params.dt_s
    recorder = _TraceRecorder() if trace else None
    can_compact = recorder is None and compactable(planner, channel, sensor)
    scratch = _scratch(params, ego)
    step = 0
    for step in range(params.n_steps):
        t = step * dt
        front_x, front_y = ego.front_x_m.copy(), ego.front_y_m.copy()
        visible = sense(params, front_x, front_y, ego, vrus)
        sensed, sensed_kinematics = sensor.observe(step, t, visible, vrus.kinematics)
        messages = channel.deliver(
            t,
            rsu_broadcast(params, ego.centre_x_m, ego.centre_y_m, vrus.kinematics),
        )
        sensor_age = sensor.age_s(step, dt)
        detected, source, estimate = fuse(
            sensed, sensed_kinematics, messages, scratch.fresh if sensor_age is None else sensor_age
        )
        work.record_detection(t, active, sensed, messages.received)
        observation = Observation(
            t, dt, *scratch.ego_view, params.routes, scratch.route_offset, detected, source, estimate, scratch.radius
        )
        old_mode = getattr(planner, "mode", None)
        old_mode = None if old_mode is None else old_mode.copy()
        command = _checked_command(planner.act(observation), params.size, planner_name)
        if old_mode is not None:
            work.record_modes(t, active, old_mode, planner.mode)
        warning = getattr(planner, "warning", None)
        if warning is not None:
            work.record_warning(t, active, warning)
        moving_before = ego.speed_mps > 0.0
        advance_vrus(params, vrus, t, front_x, front_y, ego.speed_mps, ego.station_m)
        advance_egos(params, ego, command)
        t_next = (step + 1) * dt

        centre_x, centre_y = ego.centre_x_m, ego.centre_y_m
        contact = scratch.contact
        clearance_batch(
            params.size,
            centre_x,
            centre_y,
            ego.heading_x,
            ego.heading_y,
            params.half_length_m,
            params.half_width_m,
            vrus.x_m,
            vrus.y_m,
            params.vru_radius_m,
            contact,
        )
        clearance, outline_x, outline_y = contact
        ttc = scratch.ttc
        ttc_batch(
            params.size,
            centre_x,
            centre_y,
            ego.heading_x,
            ego.heading_y,
            params.half_length_m,
            params.half_width_m,
            ego.speed_mps,
            vrus.x_m,
            vrus.y_m,
            params.vru_radius_m,
            vrus.vx_mps,
            vrus.vy_mps,
            ttc,
        )
        work.record_step(t_next, active, ego, moving_before, clearance, outline_x, outline_y, ttc, vrus)
        if recorder is not None:
            recorder.add(t_next, ego, centre_x, centre_y, vrus, detected, source, planner, clearance, ttc, command)
        running = _update_active(
            t_next,
            active,
            params.stop_on_collision,
            work.collided,
            params.stop_at_route_end,
            work.travel_time_s,
            params.duration_s,
        )
        if running == 0:
            break
        if can_compact and running < COMPACT_BELOW * active.size:
            keep = np.flatnonzero(active)
            params, ego, vrus = take_params(params, keep), take_ego(ego, keep), take_vrus(vrus, keep)
            for part in (planner, channel, sensor):
                part.compact(keep)
            metrics.merge(work)
            work = work.subset(keep, params)
            active = np.ones(keep.size, dtype=bool)
            scratch = _scratch(params, ego)
    if work is not metrics:
        metrics.merge(work)
    return BatchRun(batch, metrics, mode_names, recorder.finish() if recorder else None, step + 1)


@njit(cache=True, _nrt=False)
def _update_active(
    t_next, active, stop_on_collision, collided, stop_at_route_end, travel_time, duration
):  # pragma: no cover (compiled)
    """Stop the variants that collided (if `stop_on_collision`), completed their route (if
    `stop_at_route_end`) or reached their duration; return how many still run (serial: a reduction)."""
    running = 0
    for b in range(active.shape[0]):
        if active[b]:
            stop = (stop_on_collision[b] and collided[b]) or (stop_at_route_end[b] and travel_time[b] >= 0.0)
            active[b] = not stop and t_next < duration[b] - 1e-9
        running += 1 if active[b] else 0
    return running


def _read_only(array: np.ndarray) -> np.ndarray:
    """A read-only view, so that a planner cannot change the simulation state it observes."""
    view = array.view()
    view.flags.writeable = False
    return view


def _checked_command(command, size: int, name: str) -> np.ndarray:
    """The planner's acceleration command as a finite float array of shape [B], or one clear error."""
    try:
        array = np.asarray(command, dtype=float)
    except (TypeError, ValueError):
        array = np.full(0, np.nan)
    if array.shape != (size,) or not np.isfinite(array).all():
        raise UserInputError(
            f"planner.name: planner {name!r} must return a finite acceleration per variant, shape ({size},); "
            f"got shape {array.shape}" + ("" if array.shape != (size,) else " with NaN or infinite values")
        )
    return array


class _TraceRecorder:
    """Full time series for plots and trace files (only when asked: memory O(B x steps)).

    Row i holds the state at t_s[i] = (i + 1) dt, and the detections, planner mode and command decided at
    the start of that step (time t_s[i] - dt).
    """

    def __init__(self) -> None:
        self.rows: dict[str, list[np.ndarray]] = {}

    def _put(self, name: str, value) -> None:
        self.rows.setdefault(name, []).append(np.array(value, copy=True))

    def add(self, t, ego, centre_x, centre_y, vrus, detected, source, planner, clearance, ttc, command) -> None:
        self._put("t_s", t)
        self._put("ego_x_m", centre_x)
        self._put("ego_y_m", centre_y)
        self._put("ego_heading_x", ego.heading_x)
        self._put("ego_heading_y", ego.heading_y)
        self._put("ego_speed_mps", ego.speed_mps)
        self._put("ego_accel_mps2", ego.accel_mps2)
        self._put("ego_command_mps2", command)
        self._put("ego_curvature_per_m", ego.curvature_per_m)
        self._put("ego_station_m", ego.station_m)
        self._put("planner_mode", getattr(planner, "mode", np.zeros(ego.x_m.shape, dtype=np.int8)))
        self._put("vru_x_m", vrus.x_m)
        self._put("vru_y_m", vrus.y_m)
        self._put("vru_speed_mps", vrus.speed_mps)
        self._put("vru_detected", detected)
        self._put("vru_source", source)
        self._put("clearance_m", clearance.min(axis=1))
        self._put("ttc_s", ttc.min(axis=1))

    def finish(self) -> dict[str, np.ndarray]:
        return {name: np.stack(values) for name, values in self.rows.items()}
