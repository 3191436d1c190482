"""Euro NCAP 2026 scorecard content shared by the PNG, the terminal and the HTML report: panels per
sub-element, each scenario's grid as FC26 / LSC26 print it, titles, and what each cell shows."""

from __future__ import annotations

from vrusim.ncap.rating2026 import Assessment2026, CellResult2026, ScenarioGrid
from vrusim.ncap.rating2026 import tables as t
from vrusim.ncap.verification import VerificationReport

Key = tuple[str, str]
"""(row label, column label) of a grid cell."""
AXIS_TITLES = {"impact_location": "impact location", "target_speed": "target speed (km/h)"}


def scenario_max_points(scenario: str) -> float:
    """Maximum points of a scenario: standard + extended + robustness (t.TOTAL_POINTS)."""
    return sum(t.TOTAL_POINTS[scenario].values())


def sub_element_max_points(name: str) -> float:
    """Maximum points of a sub-element's VRU scenarios (20 and 10 for the whole Pedestrian & Cyclist ones)."""
    return sum(scenario_max_points(s) for s in t.SUB_ELEMENTS[name])


def panels(assessment: Assessment2026) -> list[tuple[str, list[str]]]:
    """(sub-element, its assessed scenarios in table order) for every sub-element with a scenario."""
    out = []
    for name, members in t.SUB_ELEMENTS.items():
        present = [s for s in members if s in assessment.scenarios]
        if present:
            out.append((name, present))
    return out


def grid_cells(assessment: Assessment2026, scenario: str) -> tuple[ScenarioGrid, dict[Key, CellResult2026]]:
    """The scenario's grid and its cell at each (row label, column label) (robustness-layer rows left out)."""
    cells = {(c.row_label, c.column_label): c for c in assessment.cells_of(scenario) if c.range != "robustness"}
    return assessment.grid(scenario), cells


def panel_title(assessment: Assessment2026, scenario: str) -> str:
    """ "CPNA day: 0.61 / 0.69" (points / max points)."""
    return f"{scenario}: {assessment.scenarios[scenario].total:.2f} / {scenario_max_points(scenario):g}"


def sub_element_title(assessment: Assessment2026, name: str) -> str:
    """ "FC Pedestrian & Cyclist: 14.11 / 20 pts" (points of the assessed scenarios / max of all)."""
    return f"{name}: {assessment.sub_elements[name]:.2f} / {sub_element_max_points(name):g} pts"


def compact_row(label: str) -> str:
    """A grid row label for narrow spaces: "10 km/h farside" -> "10 fs", "50 km/h FCW" -> "50 FCW"."""
    return label.replace(" km/h", "").replace("farside", "fs").replace("nearside", "ns")


def compact_column(label: str) -> str:
    """A grid column label without its unit: "100%" -> "100", "30 km/h" -> "30"."""
    return label.replace(" km/h", "").rstrip("%")


def kpi_text(cell: CellResult2026) -> str:
    """What a cell shows without verification: warning TTC (s) for FCW-judged cells, "✓" without impact, else the
    KPI in whole km/h (one decimal below 10); "hit" for a contact at 0 km/h (CBDA: a cyclist into the door of the
    parked VUT)."""
    if cell.criterion == t.WARNING:
        return "–" if cell.kpi is None else f"{cell.kpi:.1f}"
    if not cell.kpi:
        return "hit" if cell.colour == "red" else "✓"
    return f"{cell.kpi:.0f}" if cell.kpi >= 10.0 else f"{cell.kpi:.1f}"


def probability_text(cell: CellResult2026, verification: VerificationReport) -> str:
    """A cell's verification pass probability in whole percent, "" when it is not a verification candidate."""
    p = verification.pass_probability.get(cell.test_id)
    return "" if p is None else f"{100 * p:.0f}"
