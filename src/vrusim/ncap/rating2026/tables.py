"""The 2026 rating scheme's numbers for the VRU scenarios, as plain data (FC26 §4-5, LSC26, R26 data_model).

FC26 = Crash Avoidance - Frontal Collisions v1.1 (Oct 2025); LSC26 = Low Speed Collisions v1.1; R26 = Euro NCAP's
rating calculator `euroncap-rating-2026` 5.4.9 (`crash_avoidance/data_model.py`, `test_info.py`). Scenario names
are the calculator's (the row's `official_scenario`). tests/test_ncap_2026_assessment.py compares every table
that R26 also holds with the installed calculator.
"""

from __future__ import annotations

import math

COLOURS = ("green", "yellow", "orange", "brown", "red")
"""Cell colours, best first."""

STANDARD_SUB_SCORE: dict[str, float] = {"green": 1.0, "yellow": 0.75, "orange": 0.5, "brown": 0.25, "red": 0.0}
"""Standard-range sub-score per predicted colour (FC26 §5.3.1); also the LSC colour weight (R26 LSC_COLOR_RANK)."""

EXTENDED_SUB_SCORE: dict[str, float] = {"green": 1.0, "yellow": 1.0, "orange": 1.0, "brown": 1.0, "red": 0.0}
"""Extended-range sub-score per predicted colour (FC26 §5.3.2)."""

EXTENDED_STEPS: tuple[tuple[float, float], ...] = ((1.0, 1.0), (0.75, 0.75), (0.5, 0.5), (0.0, 0.0))
"""Extended range: (share of the range's points reached, share awarded), first match wins (FC26 §5.3.2 table:
50-75 % -> 50 %, 75-100 % -> 75 %, 100 % -> 100 %, below 50 % -> 0)."""

ROBUSTNESS_MIN_STANDARD_SHARE = 0.5
"""Robustness points need >= 50 % of the scenario's standard-range points (FC26 §5.3.3)."""

VREL_BANDS_KPH: tuple[tuple[float, tuple[tuple[float, str], ...]], ...] = (
    (10.0, ((0.0, "green"), (math.inf, "red"))),
    (20.0, ((0.0, "green"), (math.inf, "red"))),
    (30.0, ((0.0, "green"), (10.0, "brown"), (math.inf, "red"))),
    (40.0, ((0.0, "green"), (10.0, "orange"), (20.0, "brown"), (math.inf, "red"))),
    (50.0, ((0.0, "green"), (10.0, "yellow"), (20.0, "orange"), (30.0, "brown"), (math.inf, "red"))),
)
"""Vrel_impact colour bands by VUT test speed (FC26 §5.2 Figure 5-1; rows >= 50 km/h use the 50 row).

(row speed, ((upper bound km/h, colour), ...)): v takes the first colour with v <= bound, so a band is
(lower, upper] and green is exactly 0 -- the convention of FC26 §4.2.4's worked table ("Yellow 0 < v <= 10,
Orange 10 < v <= 20"). Figure 5-1 itself is an image the stored text loses: the bounds per speed row are
R26's table (`ComputedTestPoint._compute_color_logic`) and agree with §4.2.4 for >= 50 km/h.
"""

IMPACT_TOLERANCE_KPH = 2.0
"""Verification tolerance on the impact speed (FC26 §4.2.4), applied to the Vrel_impact bands only (R26)."""

FCW_MIN_TTC_S = 1.7
"""FCW rows: green when the warning comes at TTC >= 1.7 s, red below (FC26 §5.2)."""

CPMFC_MARGIN_KPH = 0.5
"""CPMFC (pedal misapplication): pass when Vimpact = 0 or Vimpact - baseline Vimpact <= 0.5 km/h (R26)."""

TAEB_TRIGGER_MPS2, TAEB_ONSET_MPS2 = -3.0, -1.0
"""TAEB: last sample of the filtered acceleration below -3 m/s², traced back to where it first crossed -1 m/s²
(FC26 Definitions)."""

MITIGATION = "Vrel_impact bands"
AVOIDANCE = "avoidance (any impact red)"
WARNING = "FCW warning TTC"
LSC_AVOIDANCE = "LSC avoidance (any impact red)"
LSC_MITIGATION = "LSC pedal misapplication"
LSC_DOORING = "LSC dooring (door retention)"
CRITERIA = (MITIGATION, AVOIDANCE, WARNING, LSC_AVOIDANCE, LSC_MITIGATION, LSC_DOORING)
DOORING_RETENTION_COLOUR = "yellow"
"""CBDA colour of a run in which the door was held and the cyclist passed untouched: R26 `_get_dooring_color`
caps retention of the driver's door at yellow (green needs every door; vrusim's door is the driver's, LSC26
§3.2.3). A door opened into the cyclist is red: warning-only and information systems, which R26 judges by the
warning TTC alone, are not modelled (UNVERIFIED)."""

TOTAL_POINTS: dict[str, dict[str, float]] = {
    "CMRs": {"standard": 1.2, "extended": 0.15, "robustness": 0.15},
    "CMRb": {"standard": 1.6, "extended": 0.2, "robustness": 0.2},
    "CMFtap": {"standard": 4.0, "extended": 0.5, "robustness": 0.5},
    "CMCscp": {"standard": 6.0, "extended": 0.75, "robustness": 0.75},
    "CPLA day": {"standard": 1.0, "extended": 0.125, "robustness": 0.25},
    "CPLA night": {"standard": 1.0, "extended": 0.125, "robustness": 0.0},
    "CBLA": {"standard": 2.0, "extended": 0.25, "robustness": 0.25},
    "CPTAfs & CPTAns": {"standard": 1.0, "extended": 0.125, "robustness": 0.125},
    "CPTAfo & CPTAno": {"standard": 1.0, "extended": 0.125, "robustness": 0.125},
    "CBTAfs & CBTAns": {"standard": 1.0, "extended": 0.125, "robustness": 0.125},
    "CBTAfo & CBTAno": {"standard": 1.0, "extended": 0.125, "robustness": 0.125},
    "CPNA day": {"standard": 0.5, "extended": 0.0625, "robustness": 0.125},
    "CPNA night": {"standard": 0.5, "extended": 0.0625, "robustness": 0.0},
    "CPFA day": {"standard": 0.5, "extended": 0.0625, "robustness": 0.125},
    "CPFA night": {"standard": 0.5, "extended": 0.0625, "robustness": 0.0},
    "CPNCO day": {"standard": 1.0, "extended": 0.125, "robustness": 0.25},
    "CPNCO night": {"standard": 1.0, "extended": 0.125, "robustness": 0.0},
    "CBNA": {"standard": 1.0, "extended": 0.125, "robustness": 0.125},
    "CBFA": {"standard": 1.0, "extended": 0.125, "robustness": 0.125},
    "CBNAO": {"standard": 2.0, "extended": 0.25, "robustness": 0.25},
    "CMCscp SfS": {"standard": 3.0},
    "CMFtap SfS": {"standard": 3.0},
    "CBNAO SfS": {"standard": 3.0},
    "CPMRCm": {"standard": 1.5},
    "CPMRCs": {"standard": 1.5},
    "CPMFC": {"standard": 2.0},
    "CBDA": {"standard": 2.0},
}
"""Points per scenario and range (FC26 §3 / LSC26 §3 scenario tables; R26 TOTAL_SCORES, night robustness None
there = 0 here: the night scenarios share the day column's robustness layers)."""

SUB_ELEMENTS: dict[str, tuple[str, ...]] = {
    "FC Pedestrian & Cyclist": (
        "CPLA day", "CPLA night", "CBLA", "CPTAfs & CPTAns", "CPTAfo & CPTAno", "CBTAfs & CBTAns",
        "CBTAfo & CBTAno", "CPNA day", "CPNA night", "CPFA day", "CPFA night", "CPNCO day", "CPNCO night",
        "CBNA", "CBFA", "CBNAO",
    ),
    "FC Car & PTW (motorcyclist part)": ("CMRs", "CMRb", "CMFtap", "CMCscp"),
    "LSC Pedestrian & Cyclist": ("CBNAO SfS", "CPMRCm", "CPMRCs", "CPMFC", "CBDA"),
    "LSC Car & PTW (motorcyclist part)": ("CMCscp SfS", "CMFtap SfS"),
}  # fmt: skip
"""The VRU scenarios of each sub-element (R26 STAGE_SUBELEMENT_TO_LOADCASES; car-to-car and lane departure are
outside vrusim and left out)."""

SUB_ELEMENT_MAX_POINTS: dict[str, float] = {"FC Pedestrian & Cyclist": 20.0, "LSC Pedestrian & Cyclist": 10.0}
"""Whole sub-elements vrusim covers (FC26 §3, LSC26 §3); the Car & PTW parts are shares of 40 and 10 points."""

LSC_SCENARIOS = frozenset(SUB_ELEMENTS["LSC Pedestrian & Cyclist"] + SUB_ELEMENTS["LSC Car & PTW (motorcyclist part)"])
FC_SCENARIOS = frozenset(SUB_ELEMENTS["FC Pedestrian & Cyclist"] + SUB_ELEMENTS["FC Car & PTW (motorcyclist part)"])

AVOIDANCE_SCENARIOS = frozenset(
    {"CPTAfs & CPTAns", "CPTAfo & CPTAno", "CBTAfs & CBTAns", "CBTAfo & CBTAno", "CMFtap", "CMCscp"}
)
"""FC scenarios judged by Vimpact: green 0, red > 0 (FC26 §5.2 criteria table)."""
LONGITUDINAL_SCENARIOS = frozenset({"CPLA day", "CPLA night", "CBLA", "CMRs", "CMRb"})
"""Scenarios whose Vrel_impact subtracts the target's longitudinal speed; in the crossing ones it is 0
(FC26 §5.2: "for CPNA, CPFA, CPNCO, CBNA, CBFA, CBNAO the velocity component of the target is always 0")."""
FCW_SCENARIOS = frozenset({"CPLA day", "CPLA night", "CBLA"})
"""Scenarios with FCW rows and an FCW / AEB choice row in R26's template (FC26 §5.2 criteria table)."""
FCW_PLAIN_ROW_SCENARIOS = frozenset({"CMRs"})
"""Scenarios whose FCW rows (CMRs 60-80 km/h, FC26 §3.1.1.3) are plain colour cells in R26's template: a warning
planner is judged by its warning TTC, another by the Vrel_impact bands (UNVERIFIED: R26 has no choice row)."""
LSC_MITIGATION_SCENARIOS = frozenset({"CPMFC"})

COLUMN_AXIS: dict[str, str] = {
    name: "target_speed" for name in ("CMFtap", "CMCscp", "CMCscp SfS", "CMFtap SfS", "CBNAO SfS", "CPMRCm", "CBDA")
}
"""Grid columns: target speed for these scenarios, impact location for the others (FC26 §3 grids)."""

STANDARD_VERIFICATION_TESTS: dict[str, int] = {
    "CMRs": 3, "CMRb": 3, "CMFtap": 3, "CMCscp": 5, "CPLA day": 3, "CPLA night": 3, "CBLA": 3,
    "CPTAfs & CPTAns": 3, "CPTAfo & CPTAno": 3, "CBTAfs & CBTAns": 3, "CBTAfo & CBTAno": 3, "CPNA day": 3,
    "CPNA night": 3, "CPFA day": 3, "CPFA night": 3, "CPNCO day": 3, "CPNCO night": 3, "CBNA": 3, "CBFA": 3,
    "CBNAO": 3,
}  # fmt: skip
"""Standard-range verification tests per scenario (FC26 §4.2.1 table; R26 STANDARD_RANGE_VERIFICATION_TEST_NUM)."""
EXTENDED_VERIFICATION_TESTS = 2
"""Extended-range verification tests per scenario (FC26 §4.2.1)."""

CORNER_CASE_TARGET_KPH: dict[str, float] = {
    "CMRb": 80.0, "CMFtap": 60.0, "CMCscp": 60.0, "CMFtap SfS": 60.0, "CMCscp SfS": 60.0,
}  # fmt: skip
"""Corner cases: cells with target speed above this are never verification tests (FC26 §4.1.2, LSC26 §4.1.2)."""

VERIFICATION_SCALE_PCT: dict[str, dict[str, dict[int, dict[int, int]]]] = {
    "standard": {
        "VTA": {
            5: {5: 100, 4: 80, 3: 60, 2: 40, 1: 20, 0: 0},
            4: {4: 100, 3: 75, 2: 50, 1: 25, 0: 0},
            3: {3: 100, 2: 67, 1: 33, 0: 0},
            2: {2: 100, 1: 50, 0: 0},
            1: {1: 100, 0: 0},
            0: {0: 100},
        },
        "Self claimed": {
            5: {5: 100, 4: 80, 3: 0, 2: 0, 1: 0, 0: 0},
            4: {4: 100, 3: 75, 2: 0, 1: 0, 0: 0},
            3: {3: 100, 2: 67, 1: 0, 0: 0},
            2: {2: 100, 1: 50, 0: 0},
            1: {1: 100, 0: 0},
            0: {0: 100},
        },
    },
    "extended": {
        "VTA": {2: {2: 100, 1: 50, 0: 0}, 1: {1: 100, 0: 0}, 0: {0: 100}},
        "Self claimed": {2: {2: 100, 1: 0, 0: 0}, 1: {1: 100, 0: 0}, 0: {0: 100}},
    },
}
"""Score % by (range, prediction method, tests run, tests passed) (FC26 §5.3.4 table; rows for fewer tests than
the table prints come from R26 SCORE_FROM_VERIFICATION_TEST_OUTCOME)."""
PREDICTION_METHODS = ("VTA", "Self claimed")

ROBUSTNESS_COLUMN: dict[str, str] = {
    "CPLA day": "CPLA", "CPLA night": "CPLA", "CBLA": "CBLA", "CPTAfs & CPTAns": "CPTA", "CPTAfo & CPTAno": "CPTA",
    "CBTAfs & CBTAns": "CBTA", "CBTAfo & CBTAno": "CBTA", "CPNA day": "CPNA", "CPNA night": "CPNA",
    "CPFA day": "CPFA", "CPFA night": "CPFA", "CPNCO day": "CPNCO", "CPNCO night": "CPNCO", "CBNA": "CBNA",
    "CBFA": "CBFA", "CBNAO": "CBNAO", "CMRs": "CMRs", "CMRb": "CMRb", "CMFtap": "CMFtap", "CMCscp": "CMCscp",
}  # fmt: skip
"""Robustness-layer column of each FC scenario (R26 robustness sheets: day and night share one)."""

_COMMON = ("Type", "Appearance", "Adverse weather conditions")
_CROSSING = ("Driver input pre-crash", "Speed", "Initial position offset", "Trajectory/Heading", *_COMMON)
APPLICABLE_LAYERS: dict[str, tuple[str, ...]] = {
    "CPLA": ("Driver input pre-crash", *_COMMON, "Illumination (Sun glare)", "Illumination (Headlamp glare)",
             "Infrastructure / Clutter"),
    "CBLA": ("Driver input pre-crash", *_COMMON, "Illumination (Night)", "Illumination (Sun glare)",
             "Infrastructure / Clutter"),
    "CPTA": ("Driver input pre-crash", "Speed", "Initial position offset", *_COMMON, "Illumination (Night)",
             "Illumination (Sun glare)", "Infrastructure / Clutter"),
    "CBTA": ("Driver input pre-crash", "Speed", "Initial position offset", *_COMMON, "Illumination (Night)",
             "Illumination (Sun glare)", "Infrastructure / Clutter"),
    "CPNA": (*_CROSSING, "Illumination (Sun glare)", "Illumination (Headlamp glare)", "Infrastructure / Clutter"),
    "CPFA": (*_CROSSING, "Illumination (Sun glare)", "Illumination (Headlamp glare)", "Infrastructure / Clutter"),
    "CPNCO": (*_CROSSING, "Illumination (Sun glare)", "Illumination (Headlamp glare)",
              "Obscuration / Obstruction"),
    "CBNA": (*_CROSSING, "Illumination (Night)", "Illumination (Sun glare)", "Infrastructure / Clutter"),
    "CBFA": (*_CROSSING, "Illumination (Night)", "Illumination (Sun glare)", "Infrastructure / Clutter"),
    "CBNAO": (*_CROSSING, "Illumination (Night)", "Illumination (Sun glare)", "Obscuration / Obstruction"),
    "CMRs": ("Driver input pre-crash", "Trajectory/Heading", *_COMMON, "Illumination (Night)",
             "Illumination (Sun glare)", "Infrastructure / Clutter"),
    "CMRb": ("Driver input pre-crash", "Acceleration", "Initial position offset", *_COMMON,
             "Illumination (Night)", "Illumination (Sun glare)", "Infrastructure / Clutter"),
    "CMFtap": ("Driver input pre-crash", "Speed", "Initial position offset", *_COMMON, "Illumination (Night)",
               "Illumination (Sun glare)"),
    "CMCscp": ("Driver input pre-crash", "Speed", *_COMMON, "Illumination (Night)", "Illumination (Sun glare)",
               "Infrastructure / Clutter"),
}  # fmt: skip
"""Applicable robustness layers per column (FC26 Appendix A, as the YES/NO cells of R26's template)."""

VERIFICATION_TOLERANCES: dict[str, float] = {
    "vut_speed_kph_max": 1.0,
    "vut_lateral_m": 0.05,
    "target_timing_s": 0.1,
}
"""Monte Carlo bounds of the lab's test tolerances (FC26 §4.3.2 table): VUT speed 0..+1.0 km/h, VUT lateral
deviation ±0.05 m, target timing ±0.1 s (the table's SCP time error, used for every scenario: UNVERIFIED)."""

UNVERIFIED: tuple[str, ...] = (
    "Vrel_impact band bounds per VUT speed row: FC26 Figure 5-1 is an image; bounds from R26, checked against "
    "FC26 §4.2.4 for >= 50 km/h only",
    "band edges: FC26 §4.2.4's table puts an edge in the band below (Yellow 0 < v <= 10); R26 puts it in the band "
    "above (10 km/h is orange there). vrusim follows the text",
    "2 km/h tolerance only on the Vrel_impact bands, not on avoidance (Vimpact) cells, as R26 does; FC26 §4.2.4 "
    "speaks of impact speeds in general",
    "CPMFC baseline: a row without `baseline_impact_speed_mps` is judged as pure avoidance (any impact red)",
    "CBDA: retention of the driver's door without contact is yellow (R26 ceiling); warning-only systems not modelled",
    "LSC corner cases (CMCscp SfS / CMFtap SfS target > 60 km/h) score 0: R26 scores LSC only from verification "
    "rows and never verifies them; LSC26's intent (OEM evidence) may differ",
    "Monte Carlo tolerance distributions: uniform within the FC26 §4.3.2 bounds; the protocol gives bounds only",
    "target timing ±0.1 s for every scenario: FC26 states it only for CCCscp/CMCscp (SCP time error)",
)
