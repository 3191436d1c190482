"""Swept fields written straight into packed batch arrays: a table of field path -> column writer.

A batch of a sweep whose every parameter has a writer here is packed without a `Scenario` per variant: its
bases are packed once, copied to every variant (`vrusim.sweep.columnar`), and each writer writes its field's
column into the arrays the field determines, recomputing derived arrays (V2X queue capacity, "ideal" flags,
whole-step latencies, the start speed that defaults to the cruise speed) with the same floating-point
operations as `vrusim.sim.params.pack`. A field without a writer, or whose writer does not apply to a base
(e.g. a VRU trigger condition the base does not use), makes its sweep build one validated `Scenario` per
variant instead (`VariantBuilder`).

Each column is checked in one pass against its field's declared rules (type, `ge`/`gt`/`le`/`lt`, finite, the
physical bound of its unit) and a writer's cross-field rules (e.g. `track_max_age_s >= latency_s + jitter_s`).
A variant a check flags is built as a `Scenario`, so its error message is exactly the per-variant one.
"""

from __future__ import annotations

import re
import types
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Union, get_args, get_origin

import annotated_types
import numpy as np
from pydantic import BaseModel

from vrusim.limits import limit
from vrusim.scenario.bounds import bound_of
from vrusim.scenario.field_paths import Step
from vrusim.scenario.schema import MAX_STEPS, Scenario
from vrusim.scenario.v2x import BernoulliLoss, resolve_channel
from vrusim.sim.params import BatchParams
from vrusim.sim.sensing.sensor_params import MAX_WHOLE_STEPS, whole_steps
from vrusim.sim.v2x import kernels as kern
from vrusim.sim.v2x.channel_params import _MODES
from vrusim.sim.v2x.loss.registry import loss_entries as _loss_entries
from vrusim.sim.v2x.loss.registry import loss_entry
from vrusim.sim.vru.point_mass import POINT_MASS

Getter = Callable[[str], np.ndarray]
"""The values of a field path for every variant of a batch: its swept column, or its base's value (None: NaN)."""
Effect = Callable[[BatchParams, Getter, str, tuple[int, ...]], None]
"""Writes a field's column (and what derives from it) into a batch copied from its bases: (params, values,
path, the path's list indices)."""
Rule = Callable[[Getter, tuple[int, ...]], np.ndarray]
"""A cross-field rule: True where a variant keeps it."""


@dataclass(frozen=True)
class FieldWriter:
    """How one swept field's column becomes packed arrays."""

    pattern: re.Pattern[str]
    effect: Effect
    applies: Callable[[Scenario, tuple[int, ...]], bool] = lambda base, index: True
    """Whether the column write is the whole effect of the field on a variant of this base."""
    rule: Rule | None = None


def _direct(name: str, column: int | None = None) -> Effect:
    """Write the column into `params.<name>` (its VRU slot `column` of the path's index when given)."""

    def effect(params: BatchParams, get: Getter, path: str, index: tuple[int, ...]) -> None:
        array = getattr(params, name)
        if column is None:
            array[:] = get(path)
        else:
            array[:, index[column]] = get(path)

    return effect


def _ego_speeds(params: BatchParams, get: Getter, path: str, index: tuple[int, ...]) -> None:
    cruise, initial = get("ego.cruise_speed_mps"), get("ego.initial_speed_mps")
    params.cruise_speed_mps[:] = cruise
    params.start_speed_mps[:] = np.where(np.isnan(initial), cruise, initial)


def _duration(params: BatchParams, get: Getter, path: str, index: tuple[int, ...]) -> None:
    params.duration_s[:] = get(path)  # n_steps: recounted by the packer


def _duration_rule(get: Getter, index: tuple[int, ...]) -> np.ndarray:
    duration, dt = get("sim.duration_s"), get("sim.dt_s")
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        return (duration >= dt) & ~(duration / dt > MAX_STEPS)


def _refresh_channel(params: BatchParams) -> None:
    """Queue capacity and the `ideal` flag from the packed channel arrays (as `pack_channel` derives them)."""
    channel, dt = params.channel, params.dt_s
    cfg = channel.cfg
    with np.errstate(over="ignore"):
        delay_steps = (cfg[:, kern.CFG_LATENCY_S] + cfg[:, kern.CFG_JITTER_S]) / dt - 1e-9
    max_delay = np.ceil(np.minimum(delay_steps, float(MAX_WHOLE_STEPS))).astype(np.int64)
    interval = np.where(
        channel.mode == _MODES["every_step"],
        1.0,
        np.where(channel.mode == _MODES["periodic"], cfg[:, kern.CFG_PERIOD_STEPS], cfg[:, kern.CFG_VAM_MIN_STEPS]),
    )
    min_interval = np.maximum(1, np.floor(interval - 1e-6).astype(np.int64))
    channel.queue_capacity[:] = max_delay // min_interval + 2
    no_loss = _loss_entries()["none"].code
    spec_ideal = (
        (channel.mode == _MODES["every_step"])
        & (cfg[:, kern.CFG_LATENCY_S] == 0.0)
        & (cfg[:, kern.CFG_JITTER_S] == 0.0)
        & (channel.loss_model == no_loss)
        & (channel.outage_count == 0)
        & (cfg[:, kern.CFG_POSITION_SIGMA_M] == 0.0)
        & (cfg[:, kern.CFG_SPEED_SIGMA_MPS] == 0.0)
        & (cfg[:, kern.CFG_MAX_AGE_S] == 0.0)
    )
    channel.ideal[:] = ~params.v2x_enabled | spec_ideal


def _channel_cfg(column: int) -> Effect:
    def effect(params: BatchParams, get: Getter, path: str, index: tuple[int, ...]) -> None:
        params.channel.cfg[:, column] = get(path)
        _refresh_channel(params)

    return effect


def _track_age_rule(get: Getter, index: tuple[int, ...]) -> np.ndarray:
    age, latency, jitter = (get(f"v2x.channel.{name}") for name in ("track_max_age_s", "latency_s", "jitter_s"))
    return ~(age < latency + jitter)


def _bernoulli_probability(params: BatchParams, get: Getter, path: str, index: tuple[int, ...]) -> None:
    params.channel.loss_params[:, 0] = get(path)
    _refresh_channel(params)


def _is_bernoulli(base: Scenario, index: tuple[int, ...]) -> bool:
    loss = resolve_channel(base.v2x.channel).loss
    return type(loss) is BernoulliLoss and loss_entry(loss).pack(loss) == (loss.probability,)


def _sensor_range(params: BatchParams, get: Getter, path: str, index: tuple[int, ...]) -> None:
    range_m, factor = get("sensor.range_m"), get("sensor.night_range_factor")
    params.sensor_range_m[:] = np.where(get("sensor.lighting") == "night", range_m * factor, range_m)


def _sensor_model(params: BatchParams, get: Getter, path: str, index: tuple[int, ...]) -> None:
    sensor = params.sensor
    sensor.latency_steps[:] = whole_steps(get("sensor.latency_s"), params.dt_s)
    sensor.detection_probability[:] = get("sensor.detection_probability")
    sensor.position_sigma_m[:] = get("sensor.position_sigma_m")
    sensor.velocity_sigma_mps[:] = get("sensor.velocity_sigma_mps")
    exact = (sensor.detection_probability == 1.0) & (sensor.position_sigma_m == 0.0)
    exact &= sensor.velocity_sigma_mps == 0.0
    sensor.ideal[:] = exact & (sensor.latency_steps == 0) & (sensor.frame_steps == 1)


def _point_mass(base: Scenario, index: tuple[int, ...]) -> bool:
    return base.vrus[index[0]].motion == POINT_MASS


def _trigger_uses(condition: str) -> Callable[[Scenario, tuple[int, ...]], bool]:
    def applies(base: Scenario, index: tuple[int, ...]) -> bool:
        return getattr(base.vrus[index[0]].trigger, condition) is not None

    return applies


_VRU = r"vrus\[(\d+)\]\."
_TRIGGERS = (
    "at_time_s",
    "ego_distance_m",
    "ego_time_to_arrival_s",
    "ego_route_m",
    "ego_speed_below_mps",
    "ego_speed_above_mps",
    "ego_standstill_s",
)
_CHANNEL_CFG = {
    "latency_s": kern.CFG_LATENCY_S,
    "jitter_s": kern.CFG_JITTER_S,
    "track_max_age_s": kern.CFG_MAX_AGE_S,
    "rsu_position_sigma_m": kern.CFG_POSITION_SIGMA_M,
    "rsu_speed_sigma_mps": kern.CFG_SPEED_SIGMA_MPS,
}


def _writers() -> tuple[FieldWriter, ...]:
    def entry(pattern: str, effect: Effect, **options: Any) -> FieldWriter:
        return FieldWriter(re.compile(pattern), effect, **options)

    table = [
        entry(r"sim\.seed", lambda params, get, path, index: None),  # the design's `seed` column is written
        entry(r"sim\.duration_s", _duration, rule=_duration_rule),
        entry(r"ego\.(cruise|initial)_speed_mps", _ego_speeds),
        entry(r"ego\.max_accel_mps2", _direct("max_accel_mps2")),
        entry(r"ego\.max_decel_mps2", _direct("max_decel_mps2")),
        entry(r"ego\.max_jerk_mps3", _direct("max_jerk_mps3")),
        entry(r"ego\.actuator_lag_s", _direct("lag_s")),
        entry(r"ego\.mass_kg", _direct("ego_mass_kg")),
        entry(r"ego\.tracking\.lateral_gain_per_m2", _direct("lateral_gain")),
        entry(r"ego\.tracking\.heading_gain_per_m", _direct("heading_gain")),
        entry(r"sensor\.(range_m|night_range_factor)", _sensor_range),
        entry(r"sensor\.(latency_s|detection_probability|position_sigma_m|velocity_sigma_mps)", _sensor_model),
        entry(r"v2x\.comm_range_m", _direct("comm_range_m")),
        entry(r"v2x\.coverage_range_m", _direct("coverage_range_m")),
        entry(r"v2x\.channel\.loss\.probability", _bernoulli_probability, applies=_is_bernoulli),
        entry(r"metrics\.tet_ttc_threshold_s", _direct("tet_ttc_threshold_s")),
        entry(_VRU + r"top_speed_mps", _direct("vru_top_speed_mps", 0), applies=_point_mass),
        entry(_VRU + r"max_accel_mps2", _direct("vru_max_accel_mps2", 0), applies=_point_mass),
        entry(_VRU + r"speed_time_constant_s", _direct("vru_tau_s", 0), applies=_point_mass),
        entry(_VRU + r"initial_speed_mps", _direct("vru_initial_speed_mps", 0), applies=_point_mass),
        entry(_VRU + r"mass_kg", _direct("vru_mass_kg", 0)),
    ]
    for name, column in _CHANNEL_CFG.items():
        rule = _track_age_rule if name in ("latency_s", "jitter_s", "track_max_age_s") else None
        table.append(entry(rf"v2x\.channel\.{name}", _channel_cfg(column), rule=rule))
    for condition in _TRIGGERS:
        table.append(
            entry(_VRU + rf"trigger\.{condition}", _direct("trigger_value", 0), applies=_trigger_uses(condition))
        )
    return tuple(table)


WRITERS = _writers()
"""Every field with a column writer, by path pattern (a VRU's index is the pattern's group)."""


@dataclass(frozen=True)
class FieldRule:
    """A field's declared rules, checked on a whole column."""

    integer: bool
    """An int field (refuses floats); else a float field (takes ints and floats)."""
    bounds: tuple[tuple[str, int | float], ...]
    """(operator, value) pairs: "ge", "gt", "le", "lt"."""
    limit_name: str | None
    """The physical bound of its unit (`vrusim.scenario.bounds`)."""

    def keeps(self, column: np.ndarray) -> np.ndarray | None:
        """True where a value keeps the rules; None when the column's type is not the field's (every variant
        then needs its own check)."""
        if column.dtype.kind not in ("i" if self.integer else "if"):
            return None
        values = column.astype(float) if column.dtype.kind == "i" and not self.integer else column
        with np.errstate(invalid="ignore"):
            ok = np.isfinite(values) if values.dtype.kind == "f" else np.ones(values.shape, dtype=bool)
            for operator, bound in self.bounds:
                ok &= getattr(np, {"ge": "greater_equal", "gt": "greater", "le": "less_equal", "lt": "less"}[operator])(
                    values, bound
                )
            if self.limit_name is not None:
                ok &= ~(np.abs(values) > limit(self.limit_name))
        return ok


_OPERATORS = {annotated_types.Ge: "ge", annotated_types.Gt: "gt", annotated_types.Le: "le", annotated_types.Lt: "lt"}


def field_rule(base: BaseModel, steps: tuple[Step, ...]) -> FieldRule | None:
    """The declared rules of the number field at `steps` of `base`, or None when it is not a plain number field
    (its values are then checked per variant)."""
    node: Any = base
    info = None
    for step in steps:
        if isinstance(step, int):
            node = node[step]
            continue
        if not isinstance(node, BaseModel) or step not in type(node).model_fields:
            return None
        info = type(node).model_fields[step]
        node = getattr(node, step)
        if step == "channel" and isinstance(node, str):
            node = resolve_channel(node)
    if info is None:
        return None
    annotation = info.annotation
    if get_origin(annotation) in (Union, types.UnionType):
        arguments = [a for a in get_args(annotation) if a is not type(None)]
        annotation = arguments[0] if len(arguments) == 1 else None
    if annotation not in (int, float):
        return None
    bounds = []
    for item in info.metadata:
        operator = _OPERATORS.get(type(item))
        if operator is None:
            if type(item).__name__ == "Strict":  # strictness is the model's anyway
                continue
            return None
        bounds.append((operator, getattr(item, operator)))  # an int bound stays exact for int fields
    return FieldRule(annotation is int, tuple(bounds), bound_of(str(steps[-1])))


def writer_for(path: str, bases: list[Scenario]) -> tuple[FieldWriter, tuple[int, ...]] | None:
    """The writer of field `path` and the path's list indices, if it applies to every base."""
    for writer in WRITERS:
        match = writer.pattern.fullmatch(path)
        if match is not None:
            index = tuple(int(group) for group in match.groups() if group is not None and group.isdigit())
            return (writer, index) if all(writer.applies(base, index) for base in bases) else None
    return None
