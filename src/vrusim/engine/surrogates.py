"""Surrogate safety measures reduced inside the step loop: TET/TIT, DRAC, lateral clearance, PET, per-VRU minima.

Per-variant rows (`SURROGATE_ROWS`) are the last rows of the engine's accumulators (`engine.accumulators`); the
kernel sees them as an [S, B] view. Per-VRU rows (`PER_VRU_ROWS`, [B, V, K]) hold each VRU slot's minima and the
state of its post-encroachment time. Memory is O(B x K). Definitions, units and sources are in docs/metrics.md
("Surrogate safety measures").
"""

from __future__ import annotations

import numpy as np

from vrusim.geometry.contact import to_local
from vrusim.kernels import batch_kernel, njit, prange

SURROGATE_ROWS = (
    ("tet_s", "sum", "dt while 0 <= min TTC <= threshold (time exposed, Minderhoud & Bovy 2001)"),
    ("tit_s2", "sum", "(threshold - min TTC) dt while 0 <= min TTC <= threshold (time integrated)"),
    ("peak_drac_mps2", "max", "max over VRUs of v_close / (2 TTC), v_close = (v_ego h - v_vru) . h > 0"),
    ("peak_drac_time_s", "at", "time of peak_drac_mps2"),
    ("min_lateral_clearance_m", "min", "|y| - w - r while a VRU centre is alongside the rectangle (|x| <= l)"),
    ("min_lateral_clearance_time_s", "at", "time of min_lateral_clearance_m"),
)
"""Per-variant rows: (name, reduction, content), reductions as in `engine.accumulators.REDUCTIONS`."""
SURROGATE_FIELDS = tuple(name for name, _, _ in SURROGATE_ROWS)
_S = {name: index for index, name in enumerate(SURROGATE_FIELDS)}
TET, TIT = _S["tet_s"], _S["tit_s2"]
DRAC, DRAC_T = _S["peak_drac_mps2"], _S["peak_drac_time_s"]
LAT, LAT_T = _S["min_lateral_clearance_m"], _S["min_lateral_clearance_time_s"]

PER_VRU_ROWS = (
    ("min_ttc_s", "smallest 2-D TTC of this VRU"),
    ("min_clearance_m", "smallest clearance of this VRU"),
    ("pet_s", "post-encroachment time (NaN: not yet known, inf: none)"),
    ("pet_in_s", "first time in the ego's corridor (NaN: not yet)"),
    ("pet_out_s", "time it left the corridor after pet_in_s (NaN: not yet)"),
    ("pet_zone_start_m", "lowest route station its disc covered while in the corridor"),
    ("pet_rear_pass_s", "time the ego's rear passed its disc before it entered (NaN: not yet)"),
    ("pet_rear_gap_m", "x + l + r at the previous step (carry)"),
)
"""Per-VRU rows [B, V, K]: (name, content)."""
PER_VRU_FIELDS = tuple(name for name, _ in PER_VRU_ROWS)
_V = {name: index for index, name in enumerate(PER_VRU_FIELDS)}
V_TTC, V_CLR, PET = _V["min_ttc_s"], _V["min_clearance_m"], _V["pet_s"]
PET_IN, PET_OUT, PET_ZONE, PET_PASS, PET_GAP = (
    _V["pet_in_s"], _V["pet_out_s"], _V["pet_zone_start_m"], _V["pet_rear_pass_s"], _V["pet_rear_gap_m"],
)  # fmt: skip


def initial_surrogates(rows: np.ndarray, slots: int) -> np.ndarray:
    """Set the per-variant rows [S, B] (zeros) to their values before the first step; return fresh per-VRU rows
    [B, V, K]."""
    rows[[DRAC_T, LAT_T]] = np.nan
    rows[LAT] = np.inf
    per_vru = np.full((rows.shape[1], len(PER_VRU_FIELDS), slots), np.nan)
    per_vru[:, [V_TTC, V_CLR, PET_ZONE]] = np.inf
    per_vru[:, PET_GAP] = -np.inf
    return per_vru


@batch_kernel
def record_surrogates(
    t,
    dt,
    active,
    speed,
    hx,
    hy,
    centre_x,
    centre_y,
    station,
    rear_to_centre,
    half_length,
    half_width,
    radius,
    vru,
    clearance,
    ttc,
    threshold,
    s,
    pv,
):  # pragma: no cover (compiled)
    """Fold one step (ending at t) into the surrogate rows `s` [S, B] and per-VRU rows `pv` [B, V, K]."""
    for b in prange(clearance.shape[0]):
        surrogates_variant(
            b,
            t,
            dt,
            active,
            speed,
            hx,
            hy,
            centre_x,
            centre_y,
            station,
            rear_to_centre,
            half_length,
            half_width,
            radius,
            vru,
            clearance,
            ttc,
            threshold,
            s,
            pv,
        )


@njit(cache=True, inline="always")
def surrogates_variant(
    b,
    t,
    dt,
    active,
    speed,
    hx,
    hy,
    centre_x,
    centre_y,
    station,
    rear_to_centre,
    half_length,
    half_width,
    radius,
    vru,
    clearance,
    ttc,
    threshold,
    s,
    pv,
):  # pragma: no cover (compiled)
    """`record_surrogates` for variant b."""
    K = clearance.shape[1]
    if not active[b]:
        return
    hl, w, v = half_length[b], half_width[b], speed[b]
    centre_station = station[b] + rear_to_centre[b]
    soonest = np.inf
    for k in range(K):
        tau, r = ttc[b, k], radius[b, k]
        soonest = min(soonest, tau)
        if tau < pv[b, V_TTC, k]:
            pv[b, V_TTC, k] = tau
        if clearance[b, k] < pv[b, V_CLR, k]:
            pv[b, V_CLR, k] = clearance[b, k]
        vx, vy = vru[2, b, k], vru[3, b, k]
        closing = v - (vx * hx[b] + vy * hy[b])
        if 0.0 < tau < np.inf and closing > 0.0:
            drac = closing / (2.0 * tau)
            if drac > s[DRAC, b]:
                s[DRAC, b], s[DRAC_T, b] = drac, t
        x, y = to_local(centre_x[b], centre_y[b], hx[b], hy[b], vru[0, b, k], vru[1, b, k])
        if abs(x) <= hl:
            lateral = abs(y) - w - r
            if lateral < s[LAT, b]:
                s[LAT, b], s[LAT_T, b] = lateral, t
        if np.isnan(pv[b, PET, k]):
            _pet_step(t, dt, v, x, y, hl, w, r, centre_station, pv, b, k)
    if 0.0 <= soonest <= threshold[b]:
        s[TET, b] += dt
        s[TIT, b] += (threshold[b] - soonest) * dt


@njit(cache=True, inline="always")
def _pet_step(t, dt, v, x, y, hl, w, r, centre_station, pv, b, k):  # pragma: no cover (compiled)
    """One step of VRU k's post-encroachment time (docs/metrics.md, "Post-encroachment time")."""
    inside = abs(y) <= w + r
    if np.isnan(pv[b, PET_IN, k]):
        gap = x + hl + r  # <= 0: the ego's rear has passed the VRU's disc
        if not inside:
            before = pv[b, PET_GAP, k]
            if before > 0.0 and gap <= 0.0:
                pv[b, PET_PASS, k] = t - dt + dt * before / (before - gap)
            pv[b, PET_GAP, k] = gap
            return
        pv[b, PET_IN, k] = t
        if gap <= 0.0:  # the ego left the zone first
            passed = pv[b, PET_PASS, k]
            pv[b, PET, k] = t - passed if passed == passed else np.inf
            return
    elif np.isnan(pv[b, PET_OUT, k]) and not inside:
        pv[b, PET_OUT, k] = t
    if np.isnan(pv[b, PET_OUT, k]):  # in the corridor: the zone grows, or both occupy it at once
        if abs(x) <= hl + r:
            pv[b, PET, k] = 0.0
        elif x > 0.0:
            pv[b, PET_ZONE, k] = min(pv[b, PET_ZONE, k], centre_station + x - r)
        return
    front = centre_station + hl
    if front >= pv[b, PET_ZONE, k]:  # the ego enters the zone the VRU left: interpolated back at speed v
        back = (front - pv[b, PET_ZONE, k]) / v if v > 0.0 else 0.0
        pv[b, PET, k] = max(t - min(back, dt) - pv[b, PET_OUT, k], 0.0)
