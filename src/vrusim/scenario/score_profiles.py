"""Named calibrations of the safety / efficiency / comfort score formulas (`vrusim.metrics.scores`, docs/metrics.md)."""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, fields

from vrusim.errors import UserInputError

MAX_CLEARANCE_THRESHOLD_M = 3.0
"""Largest allowed `clearance_threshold_m`, m: a pass with at least 3 m of clearance always keeps safety 1."""


@dataclass(frozen=True)
class ScoreProfile:
    """Free parameters of the score formulas (each range-checked when the profile is made)."""

    ttc_threshold_s: float
    loss_scale: float
    loss_exponent: float
    accel_scale_mps2: float
    jerk_scale_mps3: float
    note: str
    clearance_threshold_m: float | None = None
    """Proximity term of the safety score (`metrics.safety`), m, in (0, 3]; None: safety from TTC alone."""

    def __post_init__(self) -> None:
        for item in fields(self):
            value = getattr(self, item.name)
            if item.name == "note" or (item.name == "clearance_threshold_m" and value is None):
                continue
            if not isinstance(value, int | float) or not math.isfinite(value) or value <= 0:
                raise ValueError(f"score profile {item.name}: expected a finite number > 0, got {value!r}")
        if self.clearance_threshold_m is not None and self.clearance_threshold_m > MAX_CLEARANCE_THRESHOLD_M:
            raise ValueError(
                f"score profile clearance_threshold_m: expected at most {MAX_CLEARANCE_THRESHOLD_M} m, "
                f"got {self.clearance_threshold_m!r}"
            )


PROFILES: dict[str, ScoreProfile] = {
    "paper": ScoreProfile(
        ttc_threshold_s=1.5,
        loss_scale=0.16,
        loss_exponent=0.83,
        accel_scale_mps2=75.0,
        jerk_scale_mps3=3.62,
        clearance_threshold_m=1.5,
        note=(
            "E and C scales solved from Table II of He et al. (CPSI 2025), pedestrian-with-V2X and "
            "e-scooter-without-V2X rows; TTC 1.5 s and clearance 1.5 m from the literature (docs/metrics.md)"
        ),
    ),
    "paper-ttc": ScoreProfile(
        ttc_threshold_s=1.5,
        loss_scale=0.16,
        loss_exponent=0.83,
        accel_scale_mps2=9.44,
        jerk_scale_mps3=3.63,
        note="the `paper` profile before issue 17: safety from TTC alone (for comparison; docs/metrics.md)",
    ),
    "literature": ScoreProfile(
        ttc_threshold_s=3.0,
        loss_scale=0.2,
        loss_exponent=1.0,
        accel_scale_mps2=2.0,
        jerk_scale_mps3=2.0,
        clearance_threshold_m=2.0,
        note=(
            "round values from the literature: TTC 3 s, clearance 2 m, 20 % delay halves E, "
            "ISO 2631 / jerk 2 m/s^3 scales"
        ),
    ),
}


def profile(name: str) -> ScoreProfile:
    """A named score profile."""
    try:
        return PROFILES[name]
    except KeyError:
        raise UserInputError(f"metrics.profile: unknown profile {name!r}; expected one of {sorted(PROFILES)}") from None


def profile_dict(name: str) -> dict:
    """A profile as a plain dict (for JSON output)."""
    return {"name": name, **asdict(profile(name))}
