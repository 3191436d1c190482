"""KPI -> cell colour for the 2026 VRU tests (FC26 §5.2, LSC26, R26), and TAEB from an acceleration trace."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from vrusim.errors import UserInputError
from vrusim.ncap.rating2026 import tables as t

KPH = 1 / 3.6
"""1 km/h in m/s."""


def band_row_kph(vut_speed_kph: float) -> tuple[tuple[float, str], ...]:
    """The Vrel_impact bands of a VUT test speed: the row of the largest tabulated speed <= it (>= 50 -> 50)."""
    row = t.VREL_BANDS_KPH[0][1]
    for speed, bands in t.VREL_BANDS_KPH:
        if vut_speed_kph >= speed - 1e-9:
            row = bands
    return row


def vrel_colour(vrel_impact_kph: float, vut_speed_kph: float) -> str:
    """Colour of a relative impact speed: bands (lower, upper], green exactly 0 (FC26 §5.2, §4.2.4)."""
    for bound, colour in band_row_kph(vut_speed_kph):
        if vrel_impact_kph <= bound:
            return colour
    return "red"


def accepted(predicted: str, vrel_impact_kph: float, vut_speed_kph: float) -> bool:
    """Whether a verification Vrel_impact confirms a predicted colour within ±2 km/h (FC26 §4.2.4).

    Accepted ranges (60 km/h example of §4.2.4): green v < 2, yellow 0 < v <= 12, orange 8 < v <= 22, brown
    18 < v <= 32; red is not widened. A result better than predicted also passes (§5.3.4 "in line or beyond").
    """
    measured = vrel_colour(vrel_impact_kph, vut_speed_kph)
    if t.COLOURS.index(measured) <= t.COLOURS.index(predicted):
        return True
    lower = 0.0
    for bound, colour in band_row_kph(vut_speed_kph):
        if colour == predicted:
            if colour == "green":
                return vrel_impact_kph < bound + t.IMPACT_TOLERANCE_KPH
            return lower - t.IMPACT_TOLERANCE_KPH < vrel_impact_kph <= bound + t.IMPACT_TOLERANCE_KPH
        lower = bound
    return False


def criterion_of(row: Mapping[str, Any]) -> str:
    """The KPI that judges a row: FC26 §5.2 criteria table, LSC26; FCW rows of a planner that never warns are
    judged as "FCW declared as AEB" (avoidance), as R26 does for an AEB-declared FCW row."""
    scenario = row["official_scenario"]
    if scenario in t.LSC_MITIGATION_SCENARIOS:
        return t.LSC_MITIGATION
    if scenario == "CBDA":
        return t.LSC_DOORING
    if scenario in t.LSC_SCENARIOS:
        return t.LSC_AVOIDANCE
    if scenario not in t.FC_SCENARIOS:
        raise UserInputError(
            f"official_scenario: {scenario!r} is not a 2026 VRU scenario (expected one of "
            f"{', '.join(sorted(t.FC_SCENARIOS | t.LSC_SCENARIOS))})"
        )
    if scenario in t.AVOIDANCE_SCENARIOS or row.get("function") == "avoidance":
        return t.AVOIDANCE
    if row.get("function") == "FCW":
        if scenario in t.FCW_PLAIN_ROW_SCENARIOS:
            return t.WARNING if row.get("planner_warns") else t.MITIGATION
        if scenario not in t.FCW_SCENARIOS:
            known = sorted(t.FCW_SCENARIOS | t.FCW_PLAIN_ROW_SCENARIOS)
            raise UserInputError(f"function: FCW rows exist only in {', '.join(known)}")
        return t.WARNING if row.get("planner_warns") else t.AVOIDANCE
    return t.MITIGATION


def _impact_kph(row: Mapping[str, Any], key: str = "impact_speed_mps") -> float:
    """Impact speed of a row in km/h: 0 without a collision."""
    if not row.get("collided"):
        return 0.0
    speed = row.get(key)
    if speed is None or not math.isfinite(speed):
        raise UserInputError(f"{key}: a collided row needs a finite impact speed (test {row.get('test_id')})")
    return float(speed) / KPH


def kpi_of(row: Mapping[str, Any], criterion: str) -> float | None:
    """The row's KPI: Vrel_impact / Vimpact km/h, or the warning TTC s (None: no warning)."""
    if criterion == t.WARNING:
        ttc = row.get("warning_ttc_s")
        return None if ttc is None or not math.isfinite(ttc) else float(ttc)
    impact = _impact_kph(row)
    if criterion == t.MITIGATION and row["official_scenario"] in t.LONGITUDINAL_SCENARIOS and impact > 0:
        target = row.get("target_longitudinal_speed_mps") or 0.0
        return max(impact - float(target) / KPH, 0.0)
    return impact


def colour_of(row: Mapping[str, Any], criterion: str, kpi: float | None) -> str:
    """Cell colour from the KPI (FC26 §5.2; LSC26 via R26 for CPMFC)."""
    if criterion == t.WARNING:
        return "green" if kpi is not None and kpi >= t.FCW_MIN_TTC_S else "red"
    if criterion == t.MITIGATION:
        return vrel_colour(float(kpi or 0.0), float(row["vut_speed_kph"] or 0.0))
    if criterion == t.LSC_DOORING:
        return "red" if row.get("collided") else t.DOORING_RETENTION_COLOUR
    if criterion == t.LSC_MITIGATION and kpi:
        baseline = row.get("baseline_impact_speed_mps")
        if baseline is not None:
            return "green" if kpi - float(baseline) / KPH <= t.CPMFC_MARGIN_KPH else "red"
    return "green" if not kpi else "red"


def taeb_s(time_s: np.ndarray, accel_mps2: np.ndarray) -> float | None:
    """TAEB of a filtered longitudinal acceleration trace (FC26 Definitions), None if it never drops below -3.

    The last sample below -3 m/s², then back to where the signal first crossed -1 m/s² before it (the start of
    that braking phase). The trace must already be filtered as FC26 §1 prescribes; a row that wants TAEB must
    carry `time_s` and `accel_mps2` arrays (grid rows do not: vrusim colours do not need TAEB).
    """
    time_s, accel_mps2 = np.asarray(time_s, float), np.asarray(accel_mps2, float)
    if time_s.shape != accel_mps2.shape or time_s.ndim != 1:
        raise UserInputError("time_s / accel_mps2: two 1-D arrays of one length expected")
    below = np.flatnonzero(accel_mps2 < t.TAEB_TRIGGER_MPS2)
    if below.size == 0:
        return None
    start = int(below[-1])
    while start > 0 and accel_mps2[start - 1] < t.TAEB_ONSET_MPS2:
        start -= 1
    return float(time_s[start])
