"""Euro NCAP 2023 scorecard content shared by the PNG, the terminal and the HTML report: the grid of each
group (rows scenario, lighting and variant; columns VUT test speeds) and what each cell shows."""

from __future__ import annotations

from vrusim.ncap.assess import CRITERION_AVOIDANCE, CRITERION_FCW, AssessedTest, Assessment, GroupScore
from vrusim.ncap.scoring import POINTS_ENTRIES

CAPTION = (
    "Cells: relative impact speed (km/h; avoidance-only rows: impact speed); ✓ avoided; FCW cells: warning TTC;"
    " grey: not tested.\n"
    "Bands: 2026 protocol (v4.5.1 thresholds UNVERIFIED); split of points per scenario UNVERIFIED."
)

GROUP_TITLES = {
    "pedestrian": "Pedestrian",
    "cyclist": "Cyclist",
    "motorcyclist": "Motorcyclist",
    "escooter": "E-scooter (extension, not in the Euro NCAP total)",
}
_ORDER = {key: index for index, key in enumerate(POINTS_ENTRIES)}

Row = tuple[str, str, str]


def cell_text(test: AssessedTest, compact: bool = False) -> str:
    """What a cell shows: the warning TTC for FCW-judged cells, "✓" when avoided, else the relative impact
    speed — the impact speed for avoidance-only cells, which it decides (km/h; `compact`: whole km/h from 10
    up, for the terminal)."""
    if test.criterion == CRITERION_FCW:
        if test.warning_ttc_s is None:
            return "–" if compact else "no FCW"
        return f"{test.warning_ttc_s:.1f}" + ("s" if compact else " s")
    if not test.collided:
        return "✓"
    speed = test.impact_speed_kph if test.criterion == CRITERION_AVOIDANCE else test.relative_impact_speed_kph
    speed = speed or 0.0
    return f"{speed:.0f}" if compact and speed >= 10.0 else f"{speed:.1f}"


def row_label(row: Row) -> str:
    """ "CPNA-25 day" (plus the variant when there is one)."""
    scenario, lighting, variant = row
    return f"{scenario} {lighting}" + (f" {variant}" if variant else "")


def group_grid(tests: list[AssessedTest]) -> tuple[list[Row], list[float], dict[tuple[Row, float], AssessedTest]]:
    """Rows (table order, then variant), sorted speeds and the test of each (row, speed) cell."""
    cells = {((t.scenario, t.lighting, t.variant), t.vut_speed_kph): t for t in tests}
    rows = sorted({row for row, _ in cells}, key=lambda r: (_ORDER.get((r[0], r[1]), len(_ORDER)), r[2]))
    speeds = sorted({speed for _, speed in cells})
    return rows, speeds, cells


def panel_title(group: GroupScore) -> str:
    """Group name and points / cap (nominal points for an extension group)."""
    unit = "pts" if group.in_euro_ncap_total else "nominal pts"
    return f"{GROUP_TITLES.get(group.group, group.group)}: {group.score:.2f} / {group.max_points:g} {unit}"


def groups_with_tests(assessment: Assessment) -> list[tuple[GroupScore, list[AssessedTest]]]:
    out = []
    for group in assessment.groups:
        tests = [t for t in assessment.tests if t.group == group.group]
        if tests:
            out.append((group, tests))
    return out
