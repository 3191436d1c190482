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

from dataclasses import asdict, dataclass

import numpy as np

from vrusim.errors import UserInputError


@dataclass(frozen=True)
class ScoreProfile:
    """Free parameters of the score formulas."""

    ttc_threshold_s: float
    loss_scale: float
    loss_exponent: float
    accel_scale_mps2: float
    jerk_scale_mps3: float
    note: str


PROFILES: dict[str, ScoreProfile] = {
    "paper": ScoreProfile(
        ttc_threshold_s=1.5,
        loss_scale=0.16,
        loss_exponent=0.83,
        accel_scale_mps2=9.44,
        jerk_scale_mps3=3.63,
        note="fitted to Table II of He et al. (CPSI 2025) on the pedestrian and e-scooter cases (docs/metrics.md)",
    ),
    "literature": ScoreProfile(
        ttc_threshold_s=3.0,
        loss_scale=0.2,
        loss_exponent=1.0,
        accel_scale_mps2=2.0,
        jerk_scale_mps3=2.0,
        note="round values from the literature: TTC 3 s, 20 % delay halves E, ISO 2631 / jerk 2 m/s^3 scales",
    ),
}


def profile(name: str) -> ScoreProfile:
    """A named score profile."""
    try:
        return PROFILES[name]
    except KeyError:
        raise UserInputError(f"metrics.profile: unknown profile {name!r}; expected one of {sorted(PROFILES)}") from None


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


def profile_dict(name: str) -> dict:
    """A profile as a plain dict (for JSON output)."""
    return {"name": name, **asdict(profile(name))}
