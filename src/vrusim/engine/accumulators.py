"""Streaming run metrics: reduced inside the step loop, so memory stays O(B), never O(B x steps).

All per-variant accumulators live in one array `values[field, B]` updated by a compiled kernel; each field is
readable as an attribute (`metrics.min_ttc_s`, ...). Definitions are in docs/metrics.md.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from vrusim.engine.surrogates import (
    PER_VRU_FIELDS,
    SURROGATE_ROWS,
    initial_surrogates,
    record_surrogates,
)
from vrusim.geometry.contact import clearance_local, to_local
from vrusim.kernels import batch_kernel, njit, prange
from vrusim.sim.params import BatchParams


class Accumulator(NamedTuple):
    """One row of `RunMetrics.values`: its name (unit as suffix), how the step loop reduces it, what it holds."""

    name: str
    reduce: str
    """A key of `REDUCTIONS`."""
    doc: str


REDUCTIONS = {
    "max": "running maximum over the active steps",
    "min": "running minimum over the active steps",
    "sum": "running sum over the active steps (a time integral: value x dt)",
    "first": "time of the first active step with the event (NaN until then)",
    "at": "value or time taken at another row's event (the minimum, the first contact, the first warning)",
    "last": "value at the end of the last active step",
    "carry": "the previous step's value, kept for the next step (not a result)",
}
"""How the step loop reduces an accumulator row (docs/metrics.md)."""

ACCUMULATORS = (
    Accumulator("peak_accel_mps2", "max", "achieved acceleration a_k = (v_k - v_{k-1}) / dt (at least 0)"),
    Accumulator("peak_decel_mps2", "max", "achieved deceleration -a_k (at least 0)"),
    Accumulator("peak_jerk_mps3", "max", "|j_k|, jerk of the actuator output while moving"),
    Accumulator("peak_lateral_accel_mps2", "max", "v_k^2 |kappa_k|, kappa the commanded path curvature"),
    Accumulator("sum_accel_sq", "sum", "a_k^2 dt (m^2/s^3)"),
    Accumulator("sum_jerk_sq", "sum", "j_k^2 dt (m^2/s^5)"),
    Accumulator("elapsed_s", "sum", "dt: the active time"),
    Accumulator("moving_s", "sum", "dt of the steps in which the ego moved (speed > 0 at the start or end)"),
    Accumulator("min_clearance_m", "min", "smallest clearance over the VRUs"),
    Accumulator("min_clearance_time_s", "at", "time of min_clearance_m"),
    Accumulator("min_ttc_s", "min", "smallest 2-D TTC over the VRUs"),
    Accumulator("min_ttc_time_s", "at", "time of min_ttc_s"),
    Accumulator("travel_time_s", "first", "the rear-axle station reaches the route length"),
    Accumulator("contact_time_s", "first", "first contact (swept or clearance test)"),
    Accumulator("impact_ego_speed_mps", "at", "ego speed at contact_time_s"),
    Accumulator("impact_relative_speed_mps", "at", "|v_ego h - v_vru| at the end of the contact step"),
    Accumulator("impact_relative_longitudinal_mps", "at", "(v_ego h - v_vru) . h at the end of the contact step"),
    Accumulator("impact_local_x_m", "at", "impact point on the outline, vehicle frame x"),
    Accumulator("impact_local_y_m", "at", "impact point on the outline, vehicle frame y"),
    Accumulator("impact_vru", "at", "slot of the VRU hit (-1: none)"),
    Accumulator("first_sensor_s", "first", "any VRU perceived by the sensor"),
    Accumulator("first_v2x_s", "first", "any VRU's message received over V2X"),
    Accumulator("end_time_s", "last", "time at the end of the step"),
    Accumulator("final_speed_mps", "last", "ego speed"),
    Accumulator("final_station_m", "last", "ego rear-axle station"),
    Accumulator("prev_actuator", "carry", "actuator output (for the jerk)"),
    Accumulator("prev_clearance", "carry", "smallest clearance (contact time interpolation)"),
    Accumulator("prev_speed", "carry", "ego speed (impact speed interpolation)"),
    Accumulator("prev_ttc_s", "carry", "smallest TTC (swept contact test, TTC at warning)"),
    Accumulator("prev_ttc_vru", "carry", "slot of the VRU with the smallest TTC"),
    Accumulator("first_warning_s", "first", "forward-collision warning issued by the planner"),
    Accumulator("warning_ttc_s", "at", "TTC of the state the first warning was issued on"),
    Accumulator("impact_vru_local_x_m", "at", "centre of the VRU hit at the contact time, vehicle frame x"),
    Accumulator("impact_vru_local_y_m", "at", "centre of the VRU hit at the contact time, vehicle frame y"),
    Accumulator("impact_door", "at", "1 when the first contact was with the opened door (`ego.door`), else 0"),
)
"""Accumulator rows, declared once: the metric catalogue (`vrusim.metrics.catalog`) refers to them by name."""
SURROGATE_START = len(ACCUMULATORS)
"""First row of the surrogate safety measures (`engine.surrogates.SURROGATE_ROWS`), which follow."""
ACCUMULATORS += tuple(Accumulator(*row) for row in SURROGATE_ROWS)
FIELDS = tuple(row.name for row in ACCUMULATORS)
"""Accumulator rows; `sum_*` are integrals over time (m^2/s^3, m^2/s^5), the rest as their unit says."""
_PER_VRU_INDEX = {name: index for index, name in enumerate(PER_VRU_FIELDS)}
_I = {name: index for index, name in enumerate(FIELDS)}
# Row indices for the compiled kernels (module constants, so numba folds them in).
PEAK_A = _I["peak_accel_mps2"]
PEAK_D = _I["peak_decel_mps2"]
PEAK_J = _I["peak_jerk_mps3"]
PEAK_LAT = _I["peak_lateral_accel_mps2"]
SUM_A2 = _I["sum_accel_sq"]
SUM_J2 = _I["sum_jerk_sq"]
ELAPSED = _I["elapsed_s"]
MOVING = _I["moving_s"]
MIN_CLR = _I["min_clearance_m"]
MIN_CLR_T = _I["min_clearance_time_s"]
MIN_TTC = _I["min_ttc_s"]
MIN_TTC_T = _I["min_ttc_time_s"]
TRAVEL = _I["travel_time_s"]
CONTACT_T = _I["contact_time_s"]
IMPACT_V = _I["impact_ego_speed_mps"]
IMPACT_REL = _I["impact_relative_speed_mps"]
IMPACT_REL_LONG = _I["impact_relative_longitudinal_mps"]
IMPACT_X = _I["impact_local_x_m"]
IMPACT_Y = _I["impact_local_y_m"]
IMPACT_VRU = _I["impact_vru"]
FIRST_SENSOR = _I["first_sensor_s"]
FIRST_V2X = _I["first_v2x_s"]
END_T = _I["end_time_s"]
FINAL_V = _I["final_speed_mps"]
FINAL_S = _I["final_station_m"]
PREV_ACT = _I["prev_actuator"]
PREV_CLR = _I["prev_clearance"]
PREV_V = _I["prev_speed"]
PREV_TTC = _I["prev_ttc_s"]
PREV_TTC_VRU = _I["prev_ttc_vru"]
FIRST_WARNING = _I["first_warning_s"]
WARNING_TTC = _I["warning_ttc_s"]
IMPACT_VRU_X = _I["impact_vru_local_x_m"]
IMPACT_VRU_Y = _I["impact_vru_local_y_m"]
IMPACT_DOOR = _I["impact_door"]


class RunMetrics:
    """Per-variant summaries of a batch run, accumulated step by step."""

    def __init__(self, params: BatchParams, n_modes: int):
        B = params.size
        self.params = params
        values = np.zeros((len(FIELDS), B))
        nan_rows = (
            MIN_CLR_T,
            MIN_TTC_T,
            TRAVEL,
            CONTACT_T,
            IMPACT_V,
            IMPACT_REL,
            IMPACT_REL_LONG,
            IMPACT_X,
            IMPACT_Y,
            FIRST_SENSOR,
            FIRST_V2X,
            FIRST_WARNING,
            WARNING_TTC,
            IMPACT_VRU_X,
            IMPACT_VRU_Y,
        )
        values[list(nan_rows)] = np.nan
        values[[MIN_CLR, MIN_TTC, PREV_CLR, PREV_TTC]] = np.inf
        values[IMPACT_VRU] = -1
        values[FINAL_V] = params.start_speed_mps
        values[PREV_V] = params.start_speed_mps
        self.values = values
        self._per_vru = initial_surrogates(values[SURROGATE_START:], params.vru_slots)
        """Per-VRU rows [B, V, K] (`engine.surrogates.PER_VRU_ROWS`); slots beyond a variant's VRUs are parked."""
        self.collided = np.zeros(B, dtype=bool)
        self.first_mode_s = np.full((B, n_modes), np.nan)
        self.transitions: list[tuple[float, int, int, int]] = []
        self._variant = np.arange(B)
        """Each row's variant number in the batch `transitions` refer to (rows differ in a `subset`)."""

    def subset(self, index: np.ndarray, params: BatchParams) -> RunMetrics:
        """The metrics of rows `index` (ascending), to go on with `params` packed for them; `merge` writes
        them back. Both share one list of transitions, which keeps the variant numbers of this batch."""
        sub = RunMetrics.__new__(RunMetrics)
        sub.params = params
        sub.values = np.ascontiguousarray(self.values[:, index])
        sub._per_vru = np.ascontiguousarray(self._per_vru[index])
        sub.collided = self.collided[index]
        sub.first_mode_s = self.first_mode_s[index]
        sub.transitions = self.transitions
        sub._variant = self._variant[index]
        return sub

    def merge(self, sub: RunMetrics) -> None:
        """Write the rows of a `subset` (of this batch, possibly through other subsets) back into this one."""
        rows = sub._variant
        self.values[:, rows] = sub.values
        self._per_vru[rows] = sub._per_vru
        self.collided[rows] = sub.collided
        self.first_mode_s[rows] = sub.first_mode_s

    def merge_runs(self, parts: list[tuple[np.ndarray, RunMetrics]]) -> None:
        """Write separate runs of parts of this batch into this one: (rows of this batch, ascending; the metrics of
        a run of just those rows). Their transitions are renumbered to this batch's variants and kept in the
        per-step path's order: by step, then by variant."""
        transitions = list(self.transitions)
        for rows, part in parts:
            variants = self._variant[rows]
            transitions += [(t_s, int(variants[b]), old, new) for t_s, b, old, new in part.transitions]
            part._variant = variants
            self.merge(part)
        self.transitions = sorted(transitions, key=lambda transition: transition[:2])

    def __getattr__(self, name: str) -> np.ndarray:
        index = _I.get(name)
        if index is None:
            raise AttributeError(name)
        return self.values[index]

    def vru_row(self, name: str) -> np.ndarray:
        """A per-VRU row [B, K] of `engine.surrogates.PER_VRU_ROWS` (`min_ttc_s`, `min_clearance_m`, `pet_s`)."""
        return self._per_vru[:, _PER_VRU_INDEX[name]]

    def record_detection(self, t_s: float, active, sensed, v2x_received) -> None:
        """First times any VRU is perceived by the sensor / received over V2X."""
        _record_detection(self.params.size, t_s, active, sensed, v2x_received, self.values)

    def record_warning(self, t_s: float, active, warning) -> None:
        """First forward-collision warning of each variant, with the TTC of the state it was issued on."""
        values = self.values
        new = np.asarray(active) & np.asarray(warning, dtype=bool) & np.isnan(values[FIRST_WARNING])
        if new.any():
            values[FIRST_WARNING, new] = t_s
            values[WARNING_TTC, new] = values[PREV_TTC, new]

    def record_modes(self, t_s: float, active, old_mode, new_mode) -> None:
        """Every planner state transition, with its time."""
        rows = np.flatnonzero(active & (old_mode != new_mode))
        if rows.size:
            first = self.first_mode_s
            olds, news = (np.asarray(mode)[rows].astype(np.int64).tolist() for mode in (old_mode, new_mode))
            for b, variant, old, new in zip(rows.tolist(), self._variant[rows].tolist(), olds, news, strict=True):
                self.transitions.append((t_s, variant, old, new))
                if math.isnan(first[b, new]):
                    first[b, new] = t_s

    def record_step(
        self, t_s: float, active, ego, moving_before, clearance, outline_x, outline_y, ttc, vrus, door_hit
    ) -> None:
        """Fold one step (ending at t_s) into the summaries of the active variants; `door_hit` [B, K] marks the
        clearances that are the opened door's, not the body's."""
        p = self.params
        _record_step(
            self.params.size,
            t_s,
            self.params.dt_s,
            active,
            ego.speed_mps,
            ego.accel_mps2,
            ego.actuator_mps2,
            ego.curvature_per_m,
            ego.station_m,
            ego.heading_x,
            ego.heading_y,
            moving_before,
            self.params.route_length_m,
            clearance,
            outline_x,
            outline_y,
            ttc,
            vrus.kinematics,
            ego.centre_x_m,
            ego.centre_y_m,
            p.half_length_m,
            p.half_width_m,
            p.vru_radius_m,
            door_hit,
            self.values,
            self.collided,
        )
        record_surrogates(
            p.size, t_s, p.dt_s, active, ego.speed_mps, ego.heading_x, ego.heading_y, ego.centre_x_m, ego.centre_y_m,
            ego.station_m, p.rear_to_centre_m, p.half_length_m, p.half_width_m, p.vru_radius_m, vrus.kinematics,
            clearance, ttc, p.tet_ttc_threshold_s, self.values[SURROGATE_START:], self._per_vru,
        )  # fmt: skip


@batch_kernel
def _record_detection(t, active, sensed, received, values):  # pragma: no cover (compiled)
    for b in prange(sensed.shape[0]):
        record_detection_variant(b, t, active, sensed, received, values)


@njit(cache=True, inline="always")
def record_detection_variant(b, t, active, sensed, received, values):  # pragma: no cover (compiled)
    """`_record_detection` for variant b."""
    K = sensed.shape[1]
    if not active[b]:
        return
    for k in range(K):
        if sensed[b, k] and np.isnan(values[FIRST_SENSOR, b]):
            values[FIRST_SENSOR, b] = t
        if received[b, k] and np.isnan(values[FIRST_V2X, b]):
            values[FIRST_V2X, b] = t


@batch_kernel
def _record_step(
    t,
    dt,
    active,
    speed,
    accel,
    actuator,
    curvature,
    station,
    hx,
    hy,
    moving_before,
    route_length,
    clearance,
    outline_x,
    outline_y,
    ttc,
    vru,
    centre_x,
    centre_y,
    half_length,
    half_width,
    radius,
    door_hit,
    m,
    collided,
):  # pragma: no cover (compiled)
    for b in prange(clearance.shape[0]):
        record_step_variant(
            b,
            t,
            dt,
            active,
            speed,
            accel,
            actuator,
            curvature,
            station,
            hx,
            hy,
            moving_before,
            route_length,
            clearance,
            outline_x,
            outline_y,
            ttc,
            vru,
            centre_x,
            centre_y,
            half_length,
            half_width,
            radius,
            door_hit,
            m,
            collided,
        )


@njit(cache=True, inline="always")
def record_step_variant(
    b,
    t,
    dt,
    active,
    speed,
    accel,
    actuator,
    curvature,
    station,
    hx,
    hy,
    moving_before,
    route_length,
    clearance,
    outline_x,
    outline_y,
    ttc,
    vru,
    centre_x,
    centre_y,
    half_length,
    half_width,
    radius,
    door_hit,
    m,
    collided,
):  # pragma: no cover (compiled)
    """`_record_step` for variant b."""
    K = clearance.shape[1]
    if not active[b]:
        m[PREV_ACT, b], m[PREV_V, b] = actuator[b], speed[b]
        return
    jerk = (actuator[b] - m[PREV_ACT, b]) / dt if moving_before[b] else 0.0
    a = accel[b]
    m[PEAK_A, b] = max(m[PEAK_A, b], a)
    m[PEAK_D, b] = max(m[PEAK_D, b], -a)
    m[PEAK_J, b] = max(m[PEAK_J, b], abs(jerk))
    m[PEAK_LAT, b] = max(m[PEAK_LAT, b], speed[b] * speed[b] * abs(curvature[b]))
    m[SUM_A2, b] += a * a * dt
    m[SUM_J2, b] += jerk * jerk * dt
    m[ELAPSED, b] += dt
    if moving_before[b] or speed[b] > 0.0:
        m[MOVING, b] += dt
    closest, nearest, soonest, soonest_k = np.inf, 0, np.inf, 0
    for k in range(K):
        if clearance[b, k] < closest:
            closest, nearest = clearance[b, k], k
        if ttc[b, k] < soonest:
            soonest, soonest_k = ttc[b, k], k
    if closest < m[MIN_CLR, b]:
        m[MIN_CLR, b], m[MIN_CLR_T, b] = closest, t
    if soonest < m[MIN_TTC, b]:
        m[MIN_TTC, b], m[MIN_TTC_T, b] = soonest, t
    if np.isnan(m[TRAVEL, b]) and station[b] >= route_length[b]:
        # interpolated inside the step, so a free-flow trip takes exactly length / speed whatever dt
        before = m[FINAL_S, b]
        frac = (route_length[b] - before) / (station[b] - before) if station[b] > before else 1.0
        m[TRAVEL, b] = t - dt + min(max(frac, 0.0), 1.0) * dt
    # Swept test: the bodies also touched inside this step if, at its start, the time-to-collision under
    # constant velocities was at most dt (a fast VRU can pass through the ego between two step ends).
    swept = m[PREV_TTC, b] <= dt
    if not collided[b] and (closest <= 0.0 or swept):
        if swept:  # contact time from the TTC at the step start
            frac = m[PREV_TTC, b] / dt
            nearest = int(m[PREV_TTC_VRU, b])
        else:  # time and ego speed interpolated where the clearance crossed zero in this step
            before = m[PREV_CLR, b]
            frac = before / (before - closest) if (np.isfinite(before) and before > closest) else 1.0
        frac = min(max(frac, 0.0), 1.0)
        collided[b] = True
        m[CONTACT_T, b] = t - dt + frac * dt
        m[IMPACT_V, b] = m[PREV_V, b] + frac * (speed[b] - m[PREV_V, b])
        rvx = speed[b] * hx[b] - vru[2, b, nearest]
        rvy = speed[b] * hy[b] - vru[3, b, nearest]
        m[IMPACT_REL, b] = np.sqrt(rvx * rvx + rvy * rvy)
        m[IMPACT_REL_LONG, b] = rvx * hx[b] + rvy * hy[b]
        # the VRU's centre when the bodies met: its step-end position moved back along the relative motion
        back = (1.0 - frac) * dt
        px = vru[0, b, nearest] + rvx * back
        py = vru[1, b, nearest] + rvy * back
        lx, ly = to_local(centre_x[b], centre_y[b], hx[b], hy[b], px, py)
        m[IMPACT_VRU_X, b], m[IMPACT_VRU_Y, b] = lx, ly
        m[IMPACT_DOOR, b] = 1.0 if (door_hit[b, nearest] and not swept) else 0.0
        if swept:  # impact point where the bodies met
            _, m[IMPACT_X, b], m[IMPACT_Y, b] = clearance_local(lx, ly, half_length[b], half_width[b], 0.0)
            m[MIN_CLR, b] = min(m[MIN_CLR, b], 0.0)
        else:
            m[IMPACT_X, b], m[IMPACT_Y, b] = outline_x[b, nearest], outline_y[b, nearest]
        m[IMPACT_VRU, b] = nearest
    m[PREV_CLR, b] = closest
    m[PREV_TTC, b], m[PREV_TTC_VRU, b] = soonest, soonest_k
    m[PREV_ACT, b], m[PREV_V, b] = actuator[b], speed[b]
    m[END_T, b], m[FINAL_V, b], m[FINAL_S, b] = t, speed[b], station[b]
