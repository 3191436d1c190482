"""Euro NCAP VRU assessment of catalogue result rows: per-test colour, scenario, group and total scores.

Applies the tables of ncap/scoring.py (definitions in docs/euroncap_scoring.md). Input rows carry the
simulator's SI values (`*_mps`, `*_s`); the assessment reports speeds in km/h (`*_kph`), as the protocol
does. Absent values are None, never NaN.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import asdict, dataclass, fields
from pathlib import Path

import pyarrow as pa
import pyarrow.csv as pa_csv
import pyarrow.parquet as pq

from vrusim.errors import UserInputError
from vrusim.io.atomic import write_atomically
from vrusim.ncap.scoring import (
    BANDS_KPH,
    BANDS_UNVERIFIED,
    ESCOOTER_NOTE,
    EURO_NCAP_GROUPS,
    EXTENSION_GROUPS,
    FCW_FALLBACK_LABEL,
    FCW_MIN_TTC_S,
    GROUP_CAPS,
    MIN_BANDED_SPEED_KPH,
    POINTS_ENTRIES,
    SCENARIO_POINTS,
    SUB_SCORES,
)

MPS_TO_KPH = 3.6
"""km/h per m/s."""
KPH_DIGITS = 3
"""Speeds in km/h and TTCs are rounded to this many decimals before they meet a band edge (so 10 km/h
converted from m/s is exactly 10.0, not 10.000000000000002)."""
MITIGATION_TOLERANCE_KPH = 0.1
"""A contact counts as mitigated when the VUT lost at least this much speed before it (our choice)."""

CRITERION_BANDS = "impact speed bands"
CRITERION_AVOIDANCE = "avoidance only"
CRITERION_FCW = "FCW warning TTC"
FUNCTIONS = ("AEB", "FCW", "avoidance")
LIGHTINGS = ("day", "night")


@dataclass(frozen=True)
class AssessedTest:
    """One scored test: the input row's keys, the derived speeds, the criterion used, colour and sub-score."""

    test_id: str
    scenario: str
    group: str
    function: str
    lighting: str
    vut_speed_kph: float
    variant: str
    collided: bool
    outcome: str
    impact_speed_kph: float | None
    target_longitudinal_speed_kph: float | None
    relative_impact_speed_kph: float
    speed_reduction_kph: float
    warning_ttc_s: float | None
    planner_warns: bool
    criterion: str
    colour: str
    sub_score: float


@dataclass(frozen=True)
class ScenarioScore:
    """Score of one (scenario, lighting): sum of sub-scores x points / cells."""

    scenario: str
    lighting: str
    group: str
    cells: int
    sub_score_sum: float
    points: float
    score: float
    unverified: str


@dataclass(frozen=True)
class GroupScore:
    """Score of one group: min(sum of its scenario scores, cap). `max_points` is the cap (extension: the
    points of the assessed scenarios); `not_assessed` lists tabulated "scenario/lighting" without tests."""

    group: str
    score: float
    raw_sum: float
    cap: float | None
    max_points: float
    in_euro_ncap_total: bool
    scenarios: tuple[ScenarioScore, ...]
    not_assessed: tuple[str, ...]


@dataclass(frozen=True)
class Assessment:
    """All tests, per-group scores (Euro NCAP groups, then extensions), the Euro NCAP total and caveats."""

    tests: tuple[AssessedTest, ...]
    groups: tuple[GroupScore, ...]
    total: float
    total_max: float
    notes: tuple[str, ...] = (BANDS_UNVERIFIED, ESCOOTER_NOTE)

    def group(self, name: str) -> GroupScore:
        """The score of one group by name."""
        return next(g for g in self.groups if g.group == name)

    def to_dict(self) -> dict:
        """A JSON-ready dict (no NaN)."""
        return asdict(self)


# ----------------------------------------------------------------------------------------------- per test


def _kph(speed_mps: float | None) -> float | None:
    """km/h rounded to KPH_DIGITS; None for an absent or non-finite value."""
    if speed_mps is None or not math.isfinite(speed_mps):
        return None
    return round(float(speed_mps) * MPS_TO_KPH, KPH_DIGITS) + 0.0


def bands_row_speed_kph(vut_speed_kph: float) -> float | None:
    """Test speed of the band row that applies: the largest tabulated speed <= the test speed (None below)."""
    rows = [speed for speed, _ in BANDS_KPH if speed <= vut_speed_kph]
    return max(rows) if rows else None


def band_colour(vut_speed_kph: float, relative_impact_kph: float) -> str:
    """Colour of a relative impact speed at a VUT test speed; avoidance-only (green at 0, else red) below 10."""
    row = bands_row_speed_kph(vut_speed_kph)
    if row is None:
        return "green" if relative_impact_kph <= 0.0 else "red"
    bands = dict(BANDS_KPH)[row]
    return next(colour for bound, colour in bands if relative_impact_kph <= bound)


def _criterion(function: str, vut_speed_kph: float, planner_warns: bool) -> str:
    if function == "avoidance" or vut_speed_kph < MIN_BANDED_SPEED_KPH:
        return CRITERION_AVOIDANCE
    if function == "FCW":
        return CRITERION_FCW if planner_warns else FCW_FALLBACK_LABEL
    return CRITERION_BANDS


def _check(row: Mapping) -> None:
    test_id = row.get("test_id", "?")
    key = (row["scenario"], row["lighting"])
    if key not in POINTS_ENTRIES:
        raise ValueError(f"{test_id}: no points for scenario {key[0]!r} with lighting {key[1]!r}")
    if POINTS_ENTRIES[key].group != row["group"]:
        raise ValueError(f"{test_id}: scenario {key[0]} belongs to {POINTS_ENTRIES[key].group}, not {row['group']}")
    if row["function"] not in FUNCTIONS:
        raise ValueError(f"{test_id}: function {row['function']!r} is not one of {FUNCTIONS}")
    if row["collided"] and _kph(row["impact_speed_mps"]) is None:
        raise ValueError(f"{test_id}: collided without a finite impact speed")


def assess_test(row: Mapping) -> AssessedTest:
    """Score one catalogue result row (keys as in docs/euroncap_scoring.md)."""
    _check(row)
    vut_kph = float(row["vut_speed_kph"])
    collided = bool(row["collided"])
    impact_kph = abs(_kph(row["impact_speed_mps"])) if collided else None
    target_kph = _kph(row.get("target_longitudinal_speed_mps"))
    if impact_kph is None:
        relative, reduction = 0.0, vut_kph
    else:
        relative = round(max(impact_kph - max(target_kph or 0.0, 0.0), 0.0), KPH_DIGITS)
        reduction = round(vut_kph - impact_kph, KPH_DIGITS)
    if not collided:
        outcome = "avoided"
    elif reduction >= MITIGATION_TOLERANCE_KPH:
        outcome = "mitigated"
    else:
        outcome = "not mitigated"
    warning = row.get("warning_ttc_s")
    warning = None if warning is None or not math.isfinite(warning) else round(float(warning), KPH_DIGITS)
    planner_warns = bool(row.get("planner_warns", False))
    criterion = _criterion(row["function"], vut_kph, planner_warns)
    if criterion == CRITERION_FCW:
        colour = "green" if warning is not None and warning >= FCW_MIN_TTC_S else "red"
    elif criterion == CRITERION_AVOIDANCE:  # V_impact = 0: a VUT that has stopped may be touched (FC26)
        colour = "red" if collided and impact_kph > 0.0 else "green"
    else:
        colour = band_colour(vut_kph, relative)
    return AssessedTest(
        test_id=str(row["test_id"]),
        scenario=row["scenario"],
        group=row["group"],
        function=row["function"],
        lighting=row["lighting"],
        vut_speed_kph=vut_kph,
        variant=str(row.get("variant") or ""),
        collided=collided,
        outcome=outcome,
        impact_speed_kph=impact_kph,
        target_longitudinal_speed_kph=target_kph,
        relative_impact_speed_kph=relative + 0.0,
        speed_reduction_kph=reduction + 0.0,
        warning_ttc_s=warning,
        planner_warns=planner_warns,
        criterion=criterion,
        colour=colour,
        sub_score=SUB_SCORES[colour],
    )


# ----------------------------------------------------------------------------------------------- aggregation


def scenario_scores(tests: Iterable[AssessedTest]) -> list[ScenarioScore]:
    """Score per (scenario, lighting) present in `tests`: sum of sub-scores x points / number of cells."""
    cells: dict[tuple[str, str], list[AssessedTest]] = {}
    for test in tests:
        cells.setdefault((test.scenario, test.lighting), []).append(test)
    out = []
    for key, members in cells.items():
        total = sum(t.sub_score for t in members)
        points = SCENARIO_POINTS[key]
        out.append(
            ScenarioScore(
                scenario=key[0],
                lighting=key[1],
                group=members[0].group,
                cells=len(members),
                sub_score_sum=total,
                points=points,
                score=total * points / len(members),
                unverified=POINTS_ENTRIES[key].unverified,
            )
        )
    return out


def capped(raw_sum: float, cap: float | None) -> float:
    """A group score: the sum of its scenario scores, clipped to the cap (no cap: the sum)."""
    return raw_sum if cap is None else min(raw_sum, cap)


def _group_score(group: str, scores: list[ScenarioScore]) -> GroupScore:
    mine = tuple(s for s in scores if s.group == group)
    raw = sum(s.score for s in mine)
    cap = GROUP_CAPS.get(group)
    assessed = {(s.scenario, s.lighting) for s in mine}
    missing = tuple(f"{k[0]}/{k[1]}" for k, e in POINTS_ENTRIES.items() if e.group == group and k not in assessed)
    return GroupScore(
        group=group,
        score=capped(raw, cap),
        raw_sum=raw,
        cap=cap,
        max_points=cap if cap is not None else sum(s.points for s in mine),
        in_euro_ncap_total=group in EURO_NCAP_GROUPS,
        scenarios=mine,
        not_assessed=missing,
    )


def assess(rows: Iterable[Mapping]) -> Assessment:
    """Assess catalogue result rows: every test, every group (extensions reported separately) and the total."""
    tests = tuple(assess_test(row) for row in rows)
    scores = scenario_scores(tests)
    groups = tuple(_group_score(group, scores) for group in EURO_NCAP_GROUPS + EXTENSION_GROUPS)
    counted = [g for g in groups if g.in_euro_ncap_total]
    return Assessment(
        tests=tests,
        groups=groups,
        total=sum(g.score for g in counted),
        total_max=sum(g.max_points for g in counted),
    )


# ----------------------------------------------------------------------------------------------- files

_ARROW_TYPES = {"str": pa.string(), "float": pa.float64(), "bool": pa.bool_()}
SCHEMA = pa.schema([(f.name, _ARROW_TYPES[str(f.type).split(" |")[0]]) for f in fields(AssessedTest)])
"""Column names and types of the assessed-rows files (one row per test, fields of AssessedTest)."""
SUFFIXES = (".csv", ".parquet")


def assessed_rows(tests: Iterable[AssessedTest]) -> list[dict]:
    """The tests as plain dicts (JSON-ready)."""
    return [asdict(test) for test in tests]


def write_assessed_rows(tests: Iterable[AssessedTest], path: str | Path) -> int:
    """Write the assessed tests to `path` (.csv or .parquet by suffix), atomically; return the row count.

    UserInputError (naming the file) for another suffix or when the file cannot be written."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in SUFFIXES:
        raise UserInputError(f"{path}: unsupported file type; use a .csv or .parquet file name")
    rows = assessed_rows(tests)
    table = pa.Table.from_pylist(rows, schema=SCHEMA)
    if suffix == ".csv":
        write_atomically(path, lambda temp: pa_csv.write_csv(table, temp), "assessment")
    else:
        write_atomically(path, lambda temp: pq.write_table(table, temp), "assessment")
    return table.num_rows


def result_rows(run_rows: Iterable[Mapping], assessment: Assessment) -> list[dict]:
    """One row per test: the simulation's row joined with its assessment (colour, points, speeds in km/h)."""
    assessed = {test["test_id"]: test for test in assessed_rows(assessment.tests)}
    return [dict(row) | assessed[row["test_id"]] for row in run_rows]
