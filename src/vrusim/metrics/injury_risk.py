"""Injury risk from impact speed: the published risk curves, one table, and which curve applies to which VRU type.

A curve is either logistic in speed, `P = 1 / (1 + exp(a - b v))` (Rosén & Sander 2009), or given by the speeds at
which the published risk reaches 10, 25, 50, 75 and 90 % (Tefft 2013), interpolated linearly in the log-odds and
extrapolated with the end segments' slopes. Definitions, sources and what is extrapolated: docs/metrics.md,
"Injury risk".
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from vrusim.scenario.vru_types import VruType

KMH_PER_MPS = 3.6
MPH_PER_MPS = 3.6 / 1.609344


class RiskCurve(NamedTuple):
    """One published risk curve: P(outcome) as a function of the car's impact speed."""

    name: str
    outcome: str
    """"fatality" or "serious injury" (the source's definition in `definition`)."""
    definition: str
    speed_per_mps: float
    """The source's speed unit per m/s (3.6 for km/h)."""
    logistic: tuple[float, float] | None
    """(a, b) of P = 1 / (1 + exp(a - b v)), v in the source's unit; None for a curve given by points."""
    points: tuple[tuple[float, float], ...]
    """(speed in the source's unit, risk) points of a curve given by points; () for a logistic one."""
    source: str


CURVES: dict[str, RiskCurve] = {
    curve.name: curve
    for curve in (
        RiskCurve(
            "rosen_sander_2009",
            "fatality",
            "death of an adult pedestrian hit by the front of a passenger car",
            KMH_PER_MPS,
            (6.9, 0.090),
            (),
            "Rosén & Sander (2009), Accid. Anal. Prev. 41(3):536-542, GIDAS 1999-2007, v in km/h",
        ),
        RiskCurve(
            "tefft_2013",
            "fatality",
            "death of a pedestrian aged 15+ hit by a forward-moving car or light truck (US average, 2007-2009)",
            MPH_PER_MPS,
            None,
            ((24.1, 0.10), (32.5, 0.25), (40.6, 0.50), (48.0, 0.75), (54.6, 0.90)),
            "Tefft (2013), Accid. Anal. Prev. 50:871-878, abstract; v in mph",
        ),
        RiskCurve(
            "tefft_2013_ais4",
            "serious injury",
            "injury of AIS 4 or greater (Tefft's 'severe'), same population as tefft_2013",
            MPH_PER_MPS,
            None,
            ((17.1, 0.10), (24.9, 0.25), (33.0, 0.50), (40.8, 0.75), (48.1, 0.90)),
            "Tefft (2013), Accid. Anal. Prev. 50:871-878, abstract; v in mph",
        ),
    )
}
"""Every risk curve, by name: coefficients or published points, unit and source."""

FATALITY_CURVES = ("rosen_sander_2009", "tefft_2013")
"""The choices of `metrics.injury_risk_curve` (the fatality curve); default the first."""
SERIOUS_INJURY_CURVE = "tefft_2013_ais4"
"""The serious-injury curve (the only one published for the same speed measure with an injury threshold)."""

TYPE_USE: dict[VruType, str] = {
    VruType.PEDESTRIAN: "published: the curves are fitted to pedestrians",
    VruType.CYCLIST: "extrapolated: the pedestrian curves reused",
    VruType.E_SCOOTER: "extrapolated: the pedestrian curves reused",
    VruType.MOTORCYCLIST: "extrapolated: the pedestrian curves reused",
}
"""Which curve applies to which VRU type (every type uses the pedestrian curves; docs/metrics.md says why)."""


def risk(speed_mps: ArrayLike, curve: str) -> NDArray[np.float64]:
    """Risk in [0, 1] at an impact speed (m/s; negative speeds count as 0) on the named curve."""
    spec = CURVES[curve]
    v = np.maximum(np.asarray(speed_mps, dtype=float), 0.0) * spec.speed_per_mps
    if spec.logistic is not None:
        a, b = spec.logistic
        return 1.0 / (1.0 + np.exp(a - b * v))
    speeds = np.array([s for s, _ in spec.points])
    logits = np.log([p / (1.0 - p) for _, p in spec.points])
    inner = np.interp(v, speeds, logits)
    low = logits[0] + (v - speeds[0]) * (logits[1] - logits[0]) / (speeds[1] - speeds[0])
    high = logits[-1] + (v - speeds[-1]) * (logits[-1] - logits[-2]) / (speeds[-1] - speeds[-2])
    logit = np.where(v < speeds[0], low, np.where(v > speeds[-1], high, inner))
    return 1.0 / (1.0 + np.exp(-logit))
