"""Per-variant results of a batch run as columns (NumPy arrays), for tables, Parquet files and summaries.

Float columns hold NaN where a value is absent (no collision, never detected, ...); writers turn NaN into
a missing value (JSON null, Parquet NULL), so no NaN ever reaches a results file.
"""

from __future__ import annotations

import numpy as np

from vrusim.engine.simulate import BatchRun
from vrusim.geometry.contact import IMPACT_SIDE_NAMES, impact_side, lateral_impact_fraction
from vrusim.metrics.scores import profile, scores

FLOAT_COLUMNS = (
    "contact_time_s",
    "impact_ego_speed_mps",
    "impact_relative_speed_mps",
    "impact_relative_longitudinal_speed_mps",
    "impact_point_x_m",
    "impact_point_y_m",
    "impact_lateral_fraction",
    "first_sensor_detection_s",
    "first_v2x_message_s",
    "first_warning_s",
    "warning_ttc_s",
    "min_clearance_m",
    "min_ttc_s",
    "peak_accel_mps2",
    "peak_decel_mps2",
    "peak_jerk_mps3",
    "peak_lateral_accel_mps2",
    "rms_accel_mps2",
    "rms_jerk_mps3",
    "travel_time_s",
    "trip_time_s",
    "free_travel_time_s",
    "end_time_s",
    "final_speed_mps",
)
"""Float result columns, in table order (NaN: absent)."""
SCORE_COLUMNS = ("safety", "efficiency", "comfort")


def score_arrays(run: BatchRun) -> dict[str, np.ndarray]:
    """Scores and the derived quantities they use, per variant."""
    m, p = run.metrics, run.params
    elapsed = np.maximum(m.elapsed_s, p.dt_s)
    rms_accel = np.sqrt(m.sum_accel_sq / elapsed)
    rms_jerk = np.sqrt(m.sum_jerk_sq / elapsed)
    with np.errstate(divide="ignore"):
        free = np.where(p.cruise_speed_mps > 0, p.route_length_m / p.cruise_speed_mps, 0.0)
    # a trip not completed when the run ended is finished in thought at cruise speed (docs/metrics.md)
    station = np.minimum(p.route_length_m, m.final_station_m)
    remaining = np.where(
        p.cruise_speed_mps > 0, (p.route_length_m - station) / np.maximum(p.cruise_speed_mps, 1e-9), 0.0
    )
    travel = np.where(np.isnan(m.travel_time_s), m.end_time_s + remaining, m.travel_time_s)
    travel = np.where(p.cruise_speed_mps > 0, travel, 0.0)  # an ego told to stand still loses no time
    out = {
        "rms_accel_mps2": rms_accel,
        "rms_jerk_mps3": rms_jerk,
        "free_travel_time_s": free,
        "trip_time_s": travel,
    }
    per_profile = {}
    for b, scenario in enumerate(p.scenarios):
        per_profile.setdefault(scenario.metrics.profile, []).append(b)
    safety, efficiency, comfort = (np.zeros(p.size) for _ in range(3))
    for name, members in per_profile.items():
        idx = np.array(members)
        result = scores(
            m.collided[idx],
            m.min_ttc_s[idx],
            travel[idx],
            free[idx],
            rms_accel[idx],
            rms_jerk[idx],
            profile(name),
        )
        safety[idx], efficiency[idx], comfort[idx] = result["safety"], result["efficiency"], result["comfort"]
    out.update(safety=safety, efficiency=efficiency, comfort=comfort)
    return out


def _absent_if_not_finite(values: np.ndarray) -> np.ndarray:
    values = np.asarray(values, dtype=float)
    return np.where(np.isfinite(values), values, np.nan)


def result_columns(run: BatchRun) -> dict[str, np.ndarray]:
    """Outcome, impact, event times, metrics and scores per variant ([B] arrays; NaN: absent)."""
    m, p = run.metrics, run.params
    derived = score_arrays(run)
    collided = m.collided.copy()
    side = impact_side(m.impact_local_x_m, m.impact_local_y_m, p.half_length_m, p.half_width_m)
    names = np.array(IMPACT_SIDE_NAMES, dtype=object)
    raw = {
        "contact_time_s": m.contact_time_s,
        "impact_ego_speed_mps": m.impact_ego_speed_mps,
        "impact_relative_speed_mps": m.impact_relative_speed_mps,
        "impact_relative_longitudinal_speed_mps": m.impact_relative_longitudinal_mps,
        "impact_point_x_m": m.impact_local_x_m,
        "impact_point_y_m": m.impact_local_y_m,
        "impact_lateral_fraction": np.where(
            collided, lateral_impact_fraction(m.impact_local_y_m, p.half_width_m), np.nan
        ),
        "first_sensor_detection_s": m.first_sensor_s,
        "first_v2x_message_s": m.first_v2x_s,
        "first_warning_s": m.first_warning_s,
        "warning_ttc_s": m.warning_ttc_s,
        "min_clearance_m": m.min_clearance_m,
        "min_ttc_s": m.min_ttc_s,
        "peak_accel_mps2": m.peak_accel_mps2,
        "peak_decel_mps2": m.peak_decel_mps2,
        "peak_jerk_mps3": m.peak_jerk_mps3,
        "peak_lateral_accel_mps2": m.peak_lateral_accel_mps2,
        "rms_accel_mps2": derived["rms_accel_mps2"],
        "rms_jerk_mps3": derived["rms_jerk_mps3"],
        "travel_time_s": m.travel_time_s,
        "trip_time_s": derived["trip_time_s"],
        "free_travel_time_s": derived["free_travel_time_s"],
        "end_time_s": m.end_time_s,
        "final_speed_mps": m.final_speed_mps,
    }
    columns: dict[str, np.ndarray] = {
        "outcome": np.where(collided, "collision", "avoided").astype(object),
        "collided": collided,
        "impact_side": np.where(collided, names[np.clip(side, 0, len(names) - 1)], None),
        "impact_vru": np.where(collided, m.impact_vru, np.nan),
    }
    columns.update({name: _absent_if_not_finite(raw[name]) for name in FLOAT_COLUMNS})
    for index, mode in enumerate(run.mode_names):
        if index > 0:
            columns[f"first_{mode}_s"] = _absent_if_not_finite(m.first_mode_s[:, index])
    columns["transitions"] = np.bincount([v for _, v, _, _ in m.transitions], minlength=p.size).astype(np.int64)
    columns.update({name: np.asarray(derived[name], dtype=float) for name in SCORE_COLUMNS})
    return columns
