"""The per-step trace of a batch run: its memory estimated and budgeted before the run, then recorded into
arrays allocated once (`trace=True`, `vrusim run --trace`).

Each column is one array [rows, ...] filled row by row: no small array per step and column (about 100 bytes
of overhead each, 30 times the data of a one-variant run) and no copy when the run ends.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from vrusim.engine.stepper import BatchStepper
from vrusim.limits import check_limit
from vrusim.planners.base import Planner, planner_mode

EGO_TRACE_COLUMNS = 14
"""Per-variant columns of a trace: 9 of the ego state and command, planner mode, clearance, TTC, driver, door."""
VRU_TRACE_COLUMNS = 6
"""Per-VRU columns of a trace: x, y, speed, detected, source, V2X message age."""
BYTES_PER_VALUE = 8
"""Bytes of one traced value (float64; the int8 and boolean columns are counted as 8 too: an upper bound)."""
TRACE_COPIES = 2
"""Copies of a trace counted: the recorded arrays and one more (a trace file or a plot is made from a copy)."""
GROWTH_ROWS = 1024
"""Rows a recorder without a known length allocates first (then doubles)."""
TRACE_COLUMNS: dict[str, type] = {
    "t_s": np.float64, "ego_x_m": np.float64, "ego_y_m": np.float64, "ego_heading_x": np.float64,
    "ego_heading_y": np.float64, "ego_speed_mps": np.float64, "ego_accel_mps2": np.float64,
    "ego_command_mps2": np.float64, "ego_curvature_per_m": np.float64, "ego_station_m": np.float64,
    "planner_mode": np.int8, "vru_x_m": np.float64, "vru_y_m": np.float64, "vru_speed_mps": np.float64,
    "vru_detected": np.bool_, "vru_source": np.int8, "vru_v2x_age_s": np.float64, "clearance_m": np.float64,
    "ttc_s": np.float64,
}  # fmt: skip
"""The columns `TraceRecorder.add` records, in its order, with their dtypes, besides a driver's and a door's;
the compiled step writes the same (`engine.compiled_run`). Shapes: t_s [rows], vru_* [rows, B, K], the others
[rows, B]."""


def trace_columns(
    rows: int,
    variants: int,
    vru_slots: int,
    driver: bool = False,
    door: bool = False,
    mode_dtype: np.dtype | type = np.int8,
) -> dict[str, np.ndarray]:
    """Uninitialised trace columns of `rows` rows, as `TraceRecorder.add` records them (order, dtypes, shapes;
    a driver's and a door's float columns last when asked; `planner_mode` in the planner's mode dtype, int8 for
    the built-in planners and a planner without modes): the compiled step's arrays to write into, and the trace
    of a run that took no step (`rows` = 0)."""
    dtypes = dict(TRACE_COLUMNS, planner_mode=mode_dtype)
    if driver:
        dtypes["driver_accel_mps2"] = np.float64
    if door:
        dtypes["door_angle_rad"] = np.float64

    def shape(name: str) -> tuple[int, ...]:
        return (
            (rows,) if name == "t_s" else (rows, variants, vru_slots) if name.startswith("vru_") else (rows, variants)
        )

    return {name: np.empty(shape(name), dtype=dtype) for name, dtype in dtypes.items()}


def trace_bytes(steps: int, variants: int, vru_slots: int) -> int:
    """Upper bound of a trace's memory, bytes: copies x steps x (time + variants x (ego columns + VRUs x VRU
    columns)) x 8 bytes."""
    per_step = 1 + variants * (EGO_TRACE_COLUMNS + vru_slots * VRU_TRACE_COLUMNS)
    return TRACE_COPIES * steps * per_step * BYTES_PER_VALUE


def check_trace_budget(steps: int, variants: int, vru_slots: int) -> None:
    """Refuse a trace whose estimated memory exceeds limit `trace_bytes`, before the run starts."""
    what = f"--trace / trace=True: {steps:,} steps x {variants:,} variants x {vru_slots} VRUs"
    check_limit("trace_bytes", trace_bytes(steps, variants, vru_slots), what)


def message_age_s(stepper: BatchStepper) -> np.ndarray:
    """Age of the V2X message each ego holds about each VRU [B, K] at the last `observe`, s (NaN: none)."""
    messages = stepper.messages
    if messages is None:
        return np.full(stepper.vrus.x_m.shape, np.nan)
    return np.where(messages.received, messages.age_s, np.nan)


class TraceRecorder:
    """Full time series for plots and trace files (only when asked: memory O(B x steps)).

    Row i holds the state at t_s[i] = (i + 1) dt, and the detections, planner mode and command decided at
    the start of that step (time t_s[i] - dt). `capacity`: the most rows the run can record (its step
    count); None: unknown (the arrays grow by doubling).
    """

    def __init__(self, capacity: int | None = None) -> None:
        self.capacity = capacity if capacity is not None else GROWTH_ROWS
        self.count = 0
        self.columns: dict[str, np.ndarray] = {}

    @property
    def rows(self) -> int:
        """Number of rows recorded so far."""
        return self.count

    def _put(self, name: str, value: Any) -> None:
        value = np.asarray(value)
        column = self.columns.get(name)
        if column is None:
            column = self.columns[name] = np.empty((self.capacity, *value.shape), dtype=value.dtype)
        column[self.count] = value

    def _grow(self) -> None:
        self.capacity *= 2
        for name, column in self.columns.items():
            grown = np.empty((self.capacity, *column.shape[1:]), dtype=column.dtype)
            grown[: self.count] = column[: self.count]
            self.columns[name] = grown

    def add(self, stepper: BatchStepper, planner: Planner | None, command: np.ndarray) -> None:
        """Record the state after a step under `command` (m/s^2)."""
        if self.count == self.capacity:
            self._grow()
        ego, vrus = stepper.ego, stepper.vrus
        self._put("t_s", stepper.t_s)
        self._put("ego_x_m", ego.centre_x_m)
        self._put("ego_y_m", ego.centre_y_m)
        self._put("ego_heading_x", ego.heading_x)
        self._put("ego_heading_y", ego.heading_y)
        self._put("ego_speed_mps", ego.speed_mps)
        self._put("ego_accel_mps2", ego.accel_mps2)
        self._put("ego_command_mps2", command)
        self._put("ego_curvature_per_m", ego.curvature_per_m)
        self._put("ego_station_m", ego.station_m)
        mode = planner_mode(planner)
        self._put("planner_mode", np.zeros(ego.x_m.shape, dtype=np.int8) if mode is None else mode)
        self._put("vru_x_m", vrus.x_m)
        self._put("vru_y_m", vrus.y_m)
        self._put("vru_speed_mps", vrus.speed_mps)
        self._put("vru_detected", stepper.detected)
        self._put("vru_source", stepper.source)
        self._put("vru_v2x_age_s", message_age_s(stepper))
        self._put("clearance_m", stepper.clearance_m.min(axis=1))
        self._put("ttc_s", stepper.ttc_s.min(axis=1))
        if stepper.has_driver:
            self._put("driver_accel_mps2", stepper.driver.accel_mps2)
        if stepper.has_door:
            self._put("door_angle_rad", stepper.door.angle_rad)
        self.count += 1

    def finish(self) -> dict[str, np.ndarray]:
        """The recorded rows of every column (views: recording more later does not change them)."""
        return {name: column[: self.count] for name, column in self.columns.items()}
