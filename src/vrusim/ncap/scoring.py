"""Euro NCAP VRU scoring knowledge as plain data: colour bands, sub-scores, FCW rule, group caps, point split.

Data only: ncap/assess.py applies it. Speeds here are in km/h (`_kph`) because the protocol states them so;
the assessment converts the simulator's m/s once on entry. Derivations and sources are in
docs/euroncap_scoring.md; the spec is shared/reference/euroncap_vru.md (§6). Anything the spec marks
UNVERIFIED carries an `unverified` note here and in the docs.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from vrusim.ncap.editions.v2023 import SCENARIOS

BY_CODE = {spec.code: spec for spec in SCENARIOS}

COLOURS = ("green", "yellow", "orange", "brown", "red")
"""Euro NCAP result colours, best first."""

SUB_SCORES: dict[str, float] = {"green": 1.00, "yellow": 0.75, "orange": 0.50, "brown": 0.25, "red": 0.0}
"""Cell sub-score per colour (standard range; FC26 §5.3, R26 `predicted_score`)."""

BANDS_KPH: tuple[tuple[float, tuple[tuple[float, str], ...]], ...] = (
    (10.0, ((0.0, "green"), (math.inf, "red"))),
    (20.0, ((0.0, "green"), (math.inf, "red"))),
    (30.0, ((0.0, "green"), (10.0, "brown"), (math.inf, "red"))),
    (40.0, ((0.0, "green"), (10.0, "orange"), (20.0, "brown"), (math.inf, "red"))),
    (50.0, ((0.0, "green"), (10.0, "yellow"), (20.0, "orange"), (30.0, "brown"), (math.inf, "red"))),
)
"""Colour bands by VUT test speed: (row speed, ((upper bound of relative impact speed, colour), ...)).

A relative impact speed v takes the first colour with v <= bound (intervals (-inf, 0], (0, b1], ...).
A test speed uses the row of the largest tabulated speed <= it (our choice for the 5 km/h v4.5.1 grid:
15 -> 10, 25 -> 20, 35 -> 30, 45 -> 40, >= 50 -> 50). Values: 2026 table (FC26 §5.2, R26); the v4.5.1
thresholds are UNVERIFIED, so we use the 2026 ones.
"""
BANDS_UNVERIFIED = "UNVERIFIED: v4.5.1 thresholds unknown, 2026 (FC26/R26) bands used"

MIN_BANDED_SPEED_KPH = 10.0
"""Below this test speed (reversing CPRA at 4 and 8 km/h) a test is judged avoidance-only: green or red."""

FCW_MIN_TTC_S = 1.7
"""FCW rows: green when the warning comes at TTC >= this, else red (FC26 §5.2)."""

FCW_FALLBACK_LABEL = "AEB fallback (planner issues no warnings)"
"""Criterion of an FCW row judged by the AEB bands (FC26 allows FCW or AEB-declared for these rows)."""

EURO_NCAP_GROUPS = ("pedestrian", "cyclist", "motorcyclist")
"""Groups counted in the Euro NCAP total."""
EXTENSION_GROUPS = ("escooter",)
"""Our extension groups: scored with the same bands, reported separately, never in the Euro NCAP total."""

GROUP_CAPS: dict[str, float] = {"pedestrian": 9.0, "cyclist": 8.0, "motorcyclist": 6.0}
"""Maximum points per group, rating years 2023-2025 (verified from Euro NCAP result data, spec §6.1)."""


@dataclass(frozen=True)
class PointsEntry:
    """Points of one (scenario code, lighting): a share of an FC26 points item, scaled to the 2023-2025 cap.

    `fc26_points` are the FC26 standard + extended points of `family` at this lighting (robustness points
    left out); `cells` / `family_cells` is this code's share of the family, by nominal v4.5.1 grid cells
    (so that a full grid scores like FC26's one matrix per family).
    """

    scenario: str
    lighting: str
    group: str
    family: str
    fc26_points: float
    cells: int
    family_cells: int
    unverified: str = ""

    @property
    def weight(self) -> float:
        """FC26-equivalent weight of this code: its cell share of the family points."""
        return self.fc26_points * self.cells / self.family_cells


_SPLIT = "2023-2025 split unknown, FC26 proportion scaled to the cap"
_CPRA = "not in FC26, assumed weight 1.15625 so that CPRA gets 1 of the 9 pedestrian points"
_CBTA = "v4.5.1 CBTA grid unknown, FC26 grid (farside 10/15/20, nearside 10) assumed"
_NIGHT = "night test in v4.5.1 unknown (FC26 has it)"
_GRID = "v4.5.1 grid unknown (FC26 values)"


def _flag(*reasons: str) -> str:
    return "UNVERIFIED: " + "; ".join(reasons)


_SPLIT_TABLE: tuple[tuple[str, str, str, float, str], ...] = (
    # (scenario, lighting, FC26 family, FC26 points of the family at this lighting, UNVERIFIED note)
    # pedestrian: CPLA day/night 1.0 + 0.125 each
    ("CPLA-50", "day", "CPLA", 1.125, _flag(_SPLIT)),
    ("CPLA-25", "day", "CPLA", 1.125, _flag(_SPLIT)),
    ("CPLA-50", "night", "CPLA", 1.125, _flag(_SPLIT)),
    ("CPLA-25", "night", "CPLA", 1.125, _flag(_SPLIT, _NIGHT)),
    # CPTA 2.5 (day): farside fs/fo at 10/15/20, nearside ns/no at 10
    ("CPTAfs", "day", "CPTA", 2.5, _flag(_SPLIT)),
    ("CPTAfo", "day", "CPTA", 2.5, _flag(_SPLIT)),
    ("CPTAns", "day", "CPTA", 2.5, _flag(_SPLIT)),
    ("CPTAno", "day", "CPTA", 2.5, _flag(_SPLIT)),
    # crossing: CPNA and CPFA 0.5 + 0.0625 per lighting, CPNCO 1.0 + 0.125 per lighting; 10:5:60 (11 cells)
    ("CPNA-25", "day", "CPNA", 0.5625, _flag(_SPLIT)),
    ("CPNA-75", "day", "CPNA", 0.5625, _flag(_SPLIT)),
    ("CPNA-25", "night", "CPNA", 0.5625, _flag(_SPLIT)),
    ("CPNA-75", "night", "CPNA", 0.5625, _flag(_SPLIT)),
    ("CPFA-50", "day", "CPFA", 0.5625, _flag(_SPLIT)),
    ("CPFA-50", "night", "CPFA", 0.5625, _flag(_SPLIT, _NIGHT)),
    ("CPNCO-50", "day", "CPNCO", 1.125, _flag(_SPLIT)),
    ("CPNCO-50", "night", "CPNCO", 1.125, _flag(_SPLIT)),
    # reverse (LSC26 in 2026, no FC26 points): Cm 2 cells (4/adult, 8/child), Cs 6 cells
    ("CPRA-Cm", "day", "CPRA", 1.15625, _flag(_CPRA)),
    ("CPRA-Cs", "day", "CPRA", 1.15625, _flag(_CPRA)),
    # cyclist: CBLA 2.0 + 0.25 (day); AEB 50 % 25:5:60 (8 cells) + FCW 25 % 50:5:80 (7 cells)
    ("CBLA-50", "day", "CBLA", 2.25, _flag(_SPLIT)),
    ("CBLA-25", "day", "CBLA", 2.25, _flag(_SPLIT)),
    ("CBTAfs", "day", "CBTA", 2.5, _flag(_SPLIT, _CBTA)),
    ("CBTAfo", "day", "CBTA", 2.5, _flag(_SPLIT, _CBTA)),
    ("CBTAns", "day", "CBTA", 2.5, _flag(_SPLIT, _CBTA)),
    ("CBTAno", "day", "CBTA", 2.5, _flag(_SPLIT, _CBTA)),
    ("CBNA-50", "day", "CBNA", 1.25, _flag(_SPLIT)),
    ("CBFA-50", "day", "CBFA", 1.25, _flag(_SPLIT)),
    ("CBNAO-50", "day", "CBNAO", 2.5, _flag(_SPLIT)),
    # motorcyclist: CMRs 1.5, CMRb 2.0, CMFtap 5.0
    # CMRs: AEB rows 10:10:50 (5 cells, code CMRs) and FCW rows 60:10:80 (3 cells, code CMRs-FCW)
    ("CMRs", "day", "CMRs", 1.5, _flag(_SPLIT, _GRID)),
    ("CMRs-FCW", "day", "CMRs", 1.5, _flag(_SPLIT, _GRID)),
    ("CMRb", "day", "CMRb", 2.0, _flag(_SPLIT, _GRID)),
    ("CMFtap", "day", "CMFtap", 5.0, _flag(_SPLIT)),
)


def _entries(table: tuple[tuple[str, str, str, float, str], ...]) -> tuple[PointsEntry, ...]:
    """PointsEntries with the group and the cell counts read from the protocol tables (one source of truth):
    a code's share of its family is its grid cells over the family's cells at the same lighting."""
    family_cells: dict[tuple[str, str], int] = {}
    for scenario, lighting, family, _, _ in table:
        family_cells[family, lighting] = family_cells.get((family, lighting), 0) + len(BY_CODE[scenario].cells)
    return tuple(
        PointsEntry(
            scenario,
            lighting,
            BY_CODE[scenario].group,
            family,
            points,
            len(BY_CODE[scenario].cells),
            family_cells[family, lighting],
            note,
        )
        for scenario, lighting, family, points, note in table
    )


_ENTRIES = _entries(_SPLIT_TABLE)

ESCOOTER_POINTS_PER_SCENARIO = 1.0
"""Nominal frame of our e-scooter extension: 1 point per (scenario, lighting); not Euro NCAP points."""
ESCOOTER_NOTE = "EXTENSION: not a Euro NCAP test; nominal 1 point per scenario, outside the Euro NCAP total"
_ESCOOTER_ENTRIES: tuple[PointsEntry, ...] = tuple(
    PointsEntry(
        spec.code,
        lighting,
        "escooter",
        spec.code,
        ESCOOTER_POINTS_PER_SCENARIO,
        len(spec.cells),
        len(spec.cells),
        ESCOOTER_NOTE,
    )
    for spec in SCENARIOS
    if spec.group == "escooter"
    for lighting in spec.lighting
)


def _scaled_points(entries: tuple[PointsEntry, ...]) -> dict[tuple[str, str], float]:
    """Points per (scenario, lighting): weight x cap / sum of the group's weights (escooter: weight itself)."""
    totals: dict[str, float] = {}
    for entry in entries:
        totals[entry.group] = totals.get(entry.group, 0.0) + entry.weight
    scale = {group: GROUP_CAPS[group] / total if group in GROUP_CAPS else 1.0 for group, total in totals.items()}
    return {(e.scenario, e.lighting): e.weight * scale[e.group] for e in entries}


POINTS_ENTRIES: dict[tuple[str, str], PointsEntry] = {(e.scenario, e.lighting): e for e in _ENTRIES + _ESCOOTER_ENTRIES}
"""Every scored (scenario, lighting) with its derivation inputs and UNVERIFIED note."""

SCENARIO_POINTS: dict[tuple[str, str], float] = _scaled_points(_ENTRIES + _ESCOOTER_ENTRIES)
"""Points per (scenario code, lighting); Euro NCAP groups sum to their cap. Split UNVERIFIED (docs)."""
