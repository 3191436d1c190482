"""`assess_2026(rows)`: the 2026 VRU assessment of `ncap.grid.run_tests` rows (protocol "2026").

Each row becomes a cell (KPI, colour), each scenario gets points by range, each sub-element a total; `grid()`
lays a scenario out as the protocol prints it (rows VUT speed, columns impact location or target speed).
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Collection, Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any

from vrusim.errors import UserInputError
from vrusim.ncap.rating2026 import tables as t
from vrusim.ncap.rating2026.colours import colour_of, criterion_of, kpi_of
from vrusim.ncap.rating2026.points import ScenarioPoints, fc_points, lsc_points

RANGES = ("standard", "extended", "robustness")
_TURNS = {"fs": "farside", "ns": "nearside", "fo": "farside", "no": "nearside"}


@dataclass(frozen=True)
class CellResult2026:
    """One assessed grid cell: where it sits, what judged it, and its colour."""

    test_id: str
    scenario: str
    code: str
    row_label: str
    column_label: str
    vut_speed_kph: float | None
    impact_location: float | None
    target_speed_kph: float | None
    range: str
    function: str
    criterion: str
    kpi: float | None
    colour: str
    corner_case: bool

    def to_dict(self) -> dict[str, Any]:
        return dict(self.__dict__)


@dataclass(frozen=True)
class ScenarioGrid:
    """A scenario's colours laid out as the protocol prints them; None where no test was given."""

    scenario: str
    row_axis: str
    column_axis: str
    rows: tuple[str, ...]
    columns: tuple[str, ...]
    colours: tuple[tuple[str | None, ...], ...]
    ranges: tuple[tuple[str | None, ...], ...]


@dataclass(frozen=True)
class Assessment2026:
    """Cells, scenario points and sub-element totals of one 2026 assessment (points before verification)."""

    cells: tuple[CellResult2026, ...]
    scenarios: dict[str, ScenarioPoints]
    robustness_claims: dict[str, tuple[str, ...]] = field(default_factory=dict)

    @property
    def sub_elements(self) -> dict[str, float]:
        """Points per sub-element, over the scenarios assessed (t.SUB_ELEMENTS)."""
        return {
            name: sum(self.scenarios[s].total for s in members if s in self.scenarios)
            for name, members in t.SUB_ELEMENTS.items()
            if any(s in self.scenarios for s in members)
        }

    def cells_of(self, scenario: str) -> tuple[CellResult2026, ...]:
        return tuple(c for c in self.cells if c.scenario == scenario)

    def grid(self, scenario: str) -> ScenarioGrid:
        """The scenario's cells as a table: rows by VUT speed (then turn / function), columns by impact location
        (100 % first, as FC26 prints it) or target speed (ascending)."""
        cells = self.cells_of(scenario)
        if not cells:
            raise UserInputError(f"scenario: {scenario!r} was not assessed (have {', '.join(self.scenarios)})")
        rows = sorted({c.row_label for c in cells}, key=lambda label: _row_order(cells, label))
        axis = t.COLUMN_AXIS.get(scenario, "impact_location")
        columns = sorted({c.column_label for c in cells}, key=lambda label: _column_order(label, axis))
        where = {(c.row_label, c.column_label): c for c in cells}
        colours = tuple(tuple(getattr(where.get((r, k)), "colour", None) for k in columns) for r in rows)
        ranges = tuple(tuple(getattr(where.get((r, k)), "range", None) for k in columns) for r in rows)
        return ScenarioGrid(scenario, "VUT speed", axis, tuple(rows), tuple(columns), colours, ranges)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: cells, scenario points, sub-element totals, robustness claims, the rule sources."""
        return {
            "protocol": "2026",
            "cells": [c.to_dict() for c in self.cells],
            "scenarios": {name: p.to_dict() for name, p in self.scenarios.items()},
            "sub_elements": self.sub_elements,
            "robustness_claims": {k: list(v) for k, v in self.robustness_claims.items()},
            "sources": "FC26 §5, LSC26, R26 (docs/euroncap_scoring.md)",
            "unverified": list(t.UNVERIFIED),
        }


def _row_order(cells: tuple[CellResult2026, ...], label: str) -> tuple[float, str]:
    cell = next(c for c in cells if c.row_label == label)
    return (cell.function == "FCW", cell.vut_speed_kph or 0.0, label)


def _column_order(label: str, axis: str) -> float:
    value = float(label.split()[0].rstrip("%"))
    return -value if axis == "impact_location" else value


def _labels(row: Mapping[str, Any], scenario: str) -> tuple[str, str]:
    """(row label, column label) of a row in its scenario's grid."""
    vut = row.get("vut_speed_kph")
    parts = [str(row["grid_row"]) if row.get("grid_row") else ("SfS" if not vut else f"{float(vut):g} km/h")]
    turn = _TURNS.get(str(row.get("scenario", ""))[-2:])
    if scenario.startswith(("CPTA", "CBTA")) and turn:
        parts.append(turn)
    if row.get("function") == "FCW" and scenario in t.FCW_SCENARIOS:
        parts.append("FCW")
    if t.COLUMN_AXIS.get(scenario) == "target_speed":
        column = f"{float(row['target_speed_kph']):g} km/h"
    else:
        location = row.get("impact_location")
        if location is None:
            raise UserInputError(f"impact_location: needed for {scenario} (test {row.get('test_id')})")
        column = f"{round(float(location) * 100):d}%"
    return " ".join(parts), column


def _cell(row: Mapping[str, Any]) -> CellResult2026:
    for key in ("official_scenario", "range", "function"):
        if key not in row:
            raise UserInputError(f"{key}: every 2026 result row needs it (test {row.get('test_id')})")
    if row.get("protocol", "2026") != "2026":
        raise UserInputError(f"protocol: assess_2026 takes 2026 rows, got {row.get('protocol')!r}")
    if row["range"] not in RANGES:
        raise UserInputError(f"range: expected one of {', '.join(RANGES)}, got {row['range']!r}")
    scenario = row["official_scenario"]
    criterion = criterion_of(row)
    kpi = kpi_of(row, criterion)
    row_label, column_label = _labels(row, scenario)
    target = row.get("target_speed_kph")
    limit = t.CORNER_CASE_TARGET_KPH.get(scenario)
    return CellResult2026(
        test_id=str(row.get("test_id", "")),
        scenario=scenario,
        code=str(row.get("scenario", "")),
        row_label=row_label,
        column_label=column_label,
        vut_speed_kph=row.get("vut_speed_kph"),
        impact_location=row.get("impact_location"),
        target_speed_kph=target,
        range=row["range"],
        function=row["function"],
        criterion=criterion,
        kpi=kpi,
        colour=colour_of(row, criterion, kpi),
        corner_case=limit is not None and target is not None and float(target) > limit,
    )


def scenario_points(scenario: str, cells: Iterable[CellResult2026], claimed: Collection[str] = ()) -> ScenarioPoints:
    """Points of one scenario from its cells' colours."""
    cells = list(cells)
    if scenario in t.LSC_SCENARIOS:
        return lsc_points(scenario, [c.colour for c in cells], [c.corner_case for c in cells])
    standard = [c.colour for c in cells if c.range == "standard"]
    extended = [c.colour for c in cells if c.range == "extended"]
    return fc_points(scenario, standard, extended, claimed)


def assess_2026(
    rows: Iterable[Mapping[str, Any]], robustness_claims: Mapping[str, Collection[str]] | None = None
) -> Assessment2026:
    """Assess 2026 result rows. `robustness_claims`: robustness column (CPNA, CBLA, ...) -> layers predicted to
    hold (FC26 §5.2.1; vrusim simulates none, so none by default and robustness scores 0).

    Rows of the robustness range are layer tests, not grid cells: they are kept as cells but score nothing.
    """
    cells = tuple(_cell(row) for row in rows)
    if not cells:
        raise UserInputError("rows: no 2026 result rows to assess")
    claims = {k: tuple(v) for k, v in (robustness_claims or {}).items()}
    unknown = sorted(set(claims) - set(t.APPLICABLE_LAYERS))
    if unknown:
        raise UserInputError(
            f"robustness_claims: unknown columns {unknown} (expected from {list(t.APPLICABLE_LAYERS)})"
        )
    seen: dict[tuple[str, str, str], str] = {}
    for c in cells:
        key = (c.scenario, c.row_label, c.column_label)
        if key in seen and c.range != "robustness":
            raise UserInputError(f"rows: tests {seen[key]} and {c.test_id} fill the same cell {key}")
        seen[key] = c.test_id
    by_scenario: dict[str, list[CellResult2026]] = defaultdict(list)
    for c in cells:
        if c.range != "robustness":
            by_scenario[c.scenario].append(c)
    scenarios = {
        name: scenario_points(name, members, claims.get(t.ROBUSTNESS_COLUMN.get(name, ""), ()))
        for name, members in by_scenario.items()
    }
    return Assessment2026(cells, scenarios, claims)
