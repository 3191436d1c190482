"""2026 result rows built from the official calculator's own grid (template cells), with chosen colours.

Until the 2026 scenario tables land, tests make rows the way ncap.grid.run_tests would, one per template cell,
with an outcome (impact speed / warning) chosen to give the wanted colour.
"""

from __future__ import annotations

import random

from vrusim.ncap.rating2026 import tables as t
from vrusim.ncap.rating2026.colours import KPH, band_row_kph

KPI_FOR: dict[str, float] = {"green": 0.0, "yellow": 5.0, "orange": 15.0, "brown": 25.0, "red": 45.0}
"""A relative impact speed (km/h) inside each colour band at >= 50 km/h; lower rows use the same midpoints."""


def possible_colours(cell, planner_warns: bool = True) -> tuple[str, ...]:
    """The colours a cell can take (bands of its VUT speed, or green/red)."""
    scenario = cell.scenario
    if scenario in t.LSC_SCENARIOS or scenario in t.AVOIDANCE_SCENARIOS or cell.row_label.endswith("FCW"):
        return ("green", "red")
    return tuple(colour for _, colour in band_row_kph(_vut(cell)))


def _vut(cell) -> float:
    speed = cell.attributes.get("VUT speed", "SfS").split()[0]
    return 0.0 if speed == "SfS" else float(speed)


def row_for(cell, colour: str, planner_warns: bool = True, index: int = 0) -> dict:
    """A result row of the contract for a template cell with the given colour."""
    vut = _vut(cell)
    fcw = cell.row_label.endswith("FCW")
    target = (
        cell.column_label
        if t.COLUMN_AXIS.get(cell.scenario) == "target_speed"
        else cell.attributes.get("Target speed", "0 km/h")
    )
    turn = cell.attributes.get("Turn", "")
    suffix = {"Farside": "fs", "Nearside": "ns"}.get(turn, "")
    if cell.scenario.startswith(("CPTAfo", "CBTAfo")):
        suffix = {"Farside": "fo", "Nearside": "no"}.get(turn, "")
    grid_row = next((cell.attributes[k] for k in ("d", "Gap", "Distance") if k in cell.attributes), None)
    target_kph = float(str(target).split()[0])
    longitudinal = cell.scenario in t.LONGITUDINAL_SCENARIOS
    vrel = KPI_FOR[colour] if vut >= 50 else {"yellow": 5.0, "orange": 5.0, "brown": 5.0}.get(colour, KPI_FOR[colour])
    if vut == 40 and colour == "brown":
        vrel = 15.0
    collided = colour != "green" and not (fcw and planner_warns)
    return {
        "test_id": f"t{index}",
        "protocol": "2026",
        "scenario": cell.scenario.split()[0] + suffix,
        "official_scenario": cell.scenario,
        "lighting": cell.attributes.get("Day/Night", "Day").lower(),
        "vut_speed_kph": vut or None,
        "impact_location": None if "%" not in cell.column_label else float(cell.column_label[:-1]) / 100,
        "target_speed_kph": target_kph,
        "range": cell.range,
        "function": "FCW" if fcw else ("avoidance" if cell.scenario in t.AVOIDANCE_SCENARIOS else "AEB"),
        "collided": collided,
        "impact_speed_mps": (vrel + (target_kph if longitudinal else 0.0)) * KPH if collided else None,
        "target_longitudinal_speed_mps": target_kph * KPH if longitudinal else 0.0,
        "warning_ttc_s": (2.0 if colour == "green" else 1.0) if fcw and planner_warns else None,
        "planner_warns": planner_warns,
        "variant": None,
        "grid_row": grid_row,
    }


def rows_for(cells, pick, planner_warns: bool = True) -> list[dict]:
    """One row per cell, colour = pick(cell, possible colours)."""
    rows = []
    for index, cell in enumerate(cells):
        rows.append(row_for(cell, pick(cell, possible_colours(cell, planner_warns)), planner_warns, index))
    return rows


def seeded(seed: int):
    """A colour picker drawing uniformly among a cell's possible colours."""
    rng = random.Random(seed)
    return lambda cell, options: rng.choice(options)
