"""Euro NCAP 2026 crash-avoidance assessment of VRU tests: KPI -> cell colour -> points (FC26 §5, LSC26, R26).

`tables` holds the protocol's numbers, `colours` turns a result row into a cell colour, `points` the cell
colours into scenario and sub-element points, `assessment` ties them together (`assess_2026`).
Sources and the UNVERIFIED items are listed in docs/euroncap_scoring.md ("2026 assessment").
"""

from vrusim.ncap.rating2026.assessment import Assessment2026, CellResult2026, ScenarioGrid, assess_2026

__all__ = ["Assessment2026", "CellResult2026", "ScenarioGrid", "assess_2026"]
