"""One summary row per variant: outcome, event times, metrics and scores; absent values are None, never NaN."""

from __future__ import annotations

import math

import numpy as np

from vrusim.metrics.scores import profile, scores
from vrusim.sim.contact import IMPACT_SIDE_NAMES, impact_side, lateral_impact_fraction
from vrusim.sim.engine import BatchRun


def _value(x) -> float | None:
    x = float(x)
    return None if math.isnan(x) or math.isinf(x) else round(x, 6)


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


def summary_rows(run: BatchRun) -> list[dict]:
    """A JSON-ready dict per variant."""
    m, p = run.metrics, run.params
    derived = score_arrays(run)
    side = impact_side(m.impact_local_x_m, m.impact_local_y_m, p.half_length_m, p.half_width_m)
    fraction = lateral_impact_fraction(m.impact_local_y_m, p.half_width_m)
    per_variant: dict[int, list[dict]] = {}
    for t, v, a, c in m.transitions:
        per_variant.setdefault(v, []).append({"t_s": round(t, 6), "from": run.mode_names[a], "to": run.mode_names[c]})
    rows = []
    for b, scenario in enumerate(p.scenarios):
        collided = bool(m.collided[b])
        transitions = per_variant.get(b, [])
        first_mode = {name: _value(m.first_mode_s[b, i]) for i, name in enumerate(run.mode_names) if i > 0}
        rows.append(
            {
                "scenario": scenario.name,
                "v2x": bool(scenario.v2x.enabled),
                "planner": scenario.planner.name,
                "outcome": "collision" if collided else "avoided",
                "collided": collided,
                "contact_time_s": _value(m.contact_time_s[b]),
                "impact_ego_speed_mps": _value(m.impact_ego_speed_mps[b]),
                "impact_relative_speed_mps": _value(m.impact_relative_speed_mps[b]),
                "impact_relative_longitudinal_speed_mps": _value(m.impact_relative_longitudinal_mps[b]),
                "impact_point_x_m": _value(m.impact_local_x_m[b]),
                "impact_point_y_m": _value(m.impact_local_y_m[b]),
                "impact_side": IMPACT_SIDE_NAMES[int(side[b])] if collided else None,
                "impact_lateral_fraction": _value(fraction[b]) if collided else None,
                "impact_vru": int(m.impact_vru[b]) if collided else None,
                "first_sensor_detection_s": _value(m.first_sensor_s[b]),
                "first_v2x_message_s": _value(m.first_v2x_s[b]),
                "first_warning_s": _value(m.first_warning_s[b]),
                "warning_ttc_s": _value(m.warning_ttc_s[b]),
                "first_mode_s": first_mode,
                "transitions": transitions,
                "min_clearance_m": _value(m.min_clearance_m[b]),
                "min_ttc_s": _value(m.min_ttc_s[b]),
                "peak_accel_mps2": _value(m.peak_accel_mps2[b]),
                "peak_decel_mps2": _value(m.peak_decel_mps2[b]),
                "peak_jerk_mps3": _value(m.peak_jerk_mps3[b]),
                "peak_lateral_accel_mps2": _value(m.peak_lateral_accel_mps2[b]),
                "rms_accel_mps2": _value(derived["rms_accel_mps2"][b]),
                "rms_jerk_mps3": _value(derived["rms_jerk_mps3"][b]),
                "travel_time_s": _value(m.travel_time_s[b]),
                "trip_time_s": _value(derived["trip_time_s"][b]),
                "free_travel_time_s": _value(derived["free_travel_time_s"][b]),
                "end_time_s": _value(m.end_time_s[b]),
                "final_speed_mps": _value(m.final_speed_mps[b]),
                "safety": round(float(derived["safety"][b]), 4),
                "efficiency": round(float(derived["efficiency"][b]), 4),
                "comfort": round(float(derived["comfort"][b]), 4),
                "score_profile": scenario.metrics.profile,
            }
        )
    return rows
