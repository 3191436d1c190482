"""The safety score: the most critical of several surrogate-safety terms, each in [0, 1] (docs/metrics.md).

S = min over the terms, each 1 at or beyond its threshold and falling linearly to 0:

- TTC term        min(1, max(TTC_min, 0) / ttc_threshold_s)             a conflict in time (Hayward 1972;
                  van der Horst 1990: TTC below 1.5 s marks a serious conflict);
- proximity term  min(1, max(clearance_min, 0) / clearance_threshold_m)  a conflict in space: a pass that
                  never gets a finite TTC can still be close (passing distances: StVO §5(4) 2020, UK Highway
                  Code rule 163 2022: at least 1.5 m when passing cyclists, pedestrians, e-scooter riders).

A further input (post-encroachment time, say) is one more term in `safety_terms`: S stays the minimum.
"""

from __future__ import annotations

import numpy as np

from vrusim.scenario.score_profiles import ScoreProfile

__all__ = ["proximity_term", "safety", "safety_terms", "ttc_term"]


def ttc_term(min_ttc_s: np.ndarray, threshold_s: float) -> np.ndarray:
    """min(1, max(TTC_min, 0) / threshold); an infinite TTC (never on a collision course) gives 1."""
    return np.minimum(1.0, np.maximum(np.asarray(min_ttc_s, dtype=float), 0.0) / threshold_s)


def proximity_term(min_clearance_m: np.ndarray, threshold_m: float) -> np.ndarray:
    """min(1, max(clearance_min, 0) / threshold); no VRU ever near (infinite clearance) gives 1."""
    return np.minimum(1.0, np.maximum(np.asarray(min_clearance_m, dtype=float), 0.0) / threshold_m)


def safety_terms(
    prof: ScoreProfile, min_ttc_s: np.ndarray, min_clearance_m: np.ndarray | None
) -> dict[str, np.ndarray]:
    """The terms a profile uses, by name (a profile without `clearance_threshold_m` uses TTC only)."""
    terms = {"ttc": ttc_term(min_ttc_s, prof.ttc_threshold_s)}
    if prof.clearance_threshold_m is not None and min_clearance_m is not None:
        terms["proximity"] = proximity_term(min_clearance_m, prof.clearance_threshold_m)
    return terms


def safety(prof: ScoreProfile, min_ttc_s: np.ndarray, min_clearance_m: np.ndarray | None) -> np.ndarray:
    """The most critical (smallest) term per variant, in [0, 1]."""
    return np.minimum.reduce(list(safety_terms(prof, min_ttc_s, min_clearance_m).values()))
