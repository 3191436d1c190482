"""Named calibrations of the safety / efficiency / comfort score formulas (`vrusim.metrics.scores`, docs/metrics.md)."""

from __future__ import annotations

from dataclasses import asdict, dataclass

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


def profile_dict(name: str) -> dict:
    """A profile as a plain dict (for JSON output)."""
    return {"name": name, **asdict(profile(name))}
