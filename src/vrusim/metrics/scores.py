"""Safety, efficiency and comfort scores in [0, 1] (a collision scores 0 / 0 / 0, as in the paper).

The paper (He et al., CPSI 2025) takes its scores from He, Guo & Li (ITSC 2024) without publishing formulas.
Ours, with sources and the calibration of each free parameter, are in docs/metrics.md:

- safety     S = min(1, TTC_min / ttc_threshold_s)               (TTC against a threshold; Hayward 1972,
               van der Horst 1990: TTC below 1.5 s marks a serious conflict)
- efficiency E = 1 / (1 + (loss / loss_scale)^loss_exponent)     loss = (T_travel - T_free) / T_travel, the
               share of the trip time lost to the interaction (travel-time delay, HCM 7th ed. ch. 19)
- comfort    C = exp(-(a_rms / accel_scale)^2 - (j_rms / jerk_scale)^2)   (RMS longitudinal acceleration and
               jerk over the trip; ISO 2631-1 rates comfort by RMS acceleration, jerk after Bae et al. 2020)
"""

from __future__ import annotations

import numpy as np

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
) -> dict[str, np.ndarray]:
    """Safety, efficiency and comfort per variant (all finite, in [0, 1])."""
    safety = np.minimum(1.0, np.maximum(min_ttc_s, 0.0) / prof.ttc_threshold_s)
    with np.errstate(divide="ignore", invalid="ignore"):
        loss = np.where(travel_time_s > 0, (travel_time_s - free_travel_time_s) / travel_time_s, 0.0)
    loss = np.clip(np.nan_to_num(loss, nan=0.0), 0.0, 1.0)
    efficiency = 1.0 / (1.0 + (loss / prof.loss_scale) ** prof.loss_exponent)
    comfort = np.exp(-((rms_accel_mps2 / prof.accel_scale_mps2) ** 2) - (rms_jerk_mps3 / prof.jerk_scale_mps3) ** 2)
    zero = collided.astype(bool)
    return {
        "safety": np.where(zero, 0.0, safety),
        "efficiency": np.where(zero, 0.0, efficiency),
        "comfort": np.where(zero, 0.0, comfort),
    }
