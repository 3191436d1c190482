"""Safety, efficiency and comfort scores in [0, 1] (a collision scores 0 / 0 / 0, as in the paper).

The paper (He et al., CPSI 2025) takes its scores from He, Guo & Li (ITSC 2024) without publishing formulas.
Ours, with sources and the calibration of each free parameter, are in docs/metrics.md:

- safety     S = min(TTC term, proximity term)                   the more critical of the two (`metrics.safety`):
               min(1, TTC_min / ttc_threshold_s) (Hayward 1972, van der Horst 1990) and
               min(1, clearance_min / clearance_threshold_m) (passing distances: StVO §5(4), Highway Code r. 163)
- efficiency E = 1 / (1 + (loss / loss_scale)^loss_exponent)     loss = (T_travel - T_free) / T_travel, the
               share of the trip time lost to the interaction (travel-time delay, HCM 7th ed. ch. 19);
               0 for a stalled run (it never finishes)
- comfort    C = exp(-(a_rms / accel_scale)^2 - (j_rms / jerk_scale)^2)   (RMS longitudinal acceleration and
               jerk over the moving time; ISO 2631-1 rates comfort by RMS acceleration, jerk after Bae et al. 2020)
"""

from __future__ import annotations

import numpy as np

from vrusim.metrics.safety import safety
from vrusim.scenario.score_profiles import PROFILES, ScoreProfile, profile, profile_dict

__all__ = ["PROFILES", "ScoreProfile", "profile", "profile_dict", "scores"]


def scores(
    collided: np.ndarray,
    min_ttc_s: np.ndarray,
    travel_time_s: np.ndarray,
    free_travel_time_s: np.ndarray,
    rms_accel_mps2: np.ndarray,
    rms_jerk_mps3: np.ndarray,
    prof: ScoreProfile,
    *,
    min_clearance_m: np.ndarray,
    stalled: np.ndarray | None = None,
) -> dict[str, np.ndarray]:
    """Safety, efficiency and comfort per variant (all finite, in [0, 1]).

    `stalled` [B] bool (default none): the ego stood still short of its route end (`metrics.outcome`); its
    efficiency is 0 whatever its (infinite) trip time.
    """
    travel_time_s = np.asarray(travel_time_s, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        loss = np.where(travel_time_s > 0, (travel_time_s - free_travel_time_s) / travel_time_s, 0.0)
    loss = np.clip(np.nan_to_num(loss, nan=1.0), 0.0, 1.0)  # an infinite trip time loses the whole trip
    efficiency = 1.0 / (1.0 + (loss / prof.loss_scale) ** prof.loss_exponent)
    if stalled is not None:
        efficiency = np.where(np.asarray(stalled, dtype=bool), 0.0, efficiency)
    comfort = np.exp(-((rms_accel_mps2 / prof.accel_scale_mps2) ** 2) - (rms_jerk_mps3 / prof.jerk_scale_mps3) ** 2)
    zero = np.asarray(collided, dtype=bool)
    return {
        "safety": np.where(zero, 0.0, safety(prof, min_ttc_s, min_clearance_m)),
        "efficiency": np.where(zero, 0.0, efficiency),
        "comfort": np.where(zero, 0.0, comfort),
    }
