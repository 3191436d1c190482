"""Predictions for Euro NCAP's official 2026 rating calculator (extra `ncap2026`, package euroncap-rating-2026).

`write_predictions(assessment, path)` fills the calculator's own template (generated at run time from the
installed package, as `euroncap_rating_2026 crash_avoidance generate-template` does) with the simulated colour
of every VRU cell: the calculator reads a prediction as the colour word typed in the grid cell ("Green", ...;
`common.merge_prediction_color_sources`: the word wins, a cell fill is read only after `preprocess` re-encodes
it). It also sets "Prediction - Standard/Extended" of the VRU scenarios (VTA or Self claimed), the FCW/AEB
choice of the CPLA/CBLA choice rows, and every robustness-layer cell (YES where claimed, else NO: the
calculator divides by the number of filled layer cells, so a blank column fails). Car-to-car and lane
departure cells stay as the template has them (blank = grey: the calculator skips them and scores 0).
`official_scores(path)` runs the calculator's `preprocess` and `compute-score` on such a file.
"""

from __future__ import annotations

import contextlib
import io
import os
import shutil
import subprocess
import sys
import tempfile
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from vrusim.errors import UserInputError
from vrusim.extras import extra
from vrusim.io.atomic import write_atomically
from vrusim.ncap.rating2026 import Assessment2026
from vrusim.ncap.rating2026 import tables as t

SHEETS: dict[str, str] = {
    **{s: "FC - Ped & Cyc pred." for s in t.SUB_ELEMENTS["FC Pedestrian & Cyclist"]},
    **{s: "FC - Car & PTW pred." for s in t.SUB_ELEMENTS["FC Car & PTW (motorcyclist part)"]},
    **{s: "LSC - Ped & Cyc pred." for s in t.SUB_ELEMENTS["LSC Pedestrian & Cyclist"]},
    **{s: "LSC - Car & PTW pred." for s in t.SUB_ELEMENTS["LSC Car & PTW (motorcyclist part)"]},
}
"""Prediction sheet of each VRU scenario in the calculator's template."""
ROBUSTNESS_SHEETS = ("FC - Ped & Cyc robust. pred.", "FC - Car & PTW robust. pred.")
INPUT_SHEET = "Input parameters"
NOT_PREDICTED = frozenset({"CBDA"})
"""Scenarios whose template cells vrusim leaves as they are: R26 scores CBDA from the declared vehicle response
(information / warning / retention) and door, inputs a simulation does not decide."""
PREDICTION_INPUTS = ("Prediction - Standard", "Prediction - Extended")
VRU_INPUT_SCENARIOS = frozenset(t.APPLICABLE_LAYERS)
"""The "Scenario" names of the Input parameters sheet whose prediction method vrusim sets."""
SCORE_GROUPS: dict[str, str] = {
    "CPLA day": "CPLA", "CPLA night": "CPLA", "CPTAfs & CPTAns": "CPTA", "CPTAfo & CPTAno": "CPTA",
    "CBTAfs & CBTAns": "CBTA", "CBTAfo & CBTAno": "CBTA", "CPNA day": "CPNA", "CPNA night": "CPNA",
    "CPFA day": "CPFA", "CPFA night": "CPFA", "CPNCO day": "CPNCO", "CPNCO night": "CPNCO",
}  # fmt: skip
"""How the calculator's "Scenario Scores" sheet groups scenarios (others: under their own name)."""
SUB_ELEMENT_ROWS: dict[str, tuple[str, str]] = {
    "FC Pedestrian & Cyclist": ("Frontal Collisions", "Pedestrian & cyclist"),
    "FC Car & PTW (motorcyclist part)": ("Frontal Collisions", "Car & PTW"),
    "LSC Pedestrian & Cyclist": ("Low Speed Collisions", "Pedestrian & cyclist"),
    "LSC Car & PTW (motorcyclist part)": ("Low Speed Collisions", "Car & PTW"),
}


@dataclass(frozen=True)
class TemplateCell:
    """A VRU grid cell of the calculator's template: where it is, its range, and its grid labels."""

    scenario: str
    sheet: str
    row: int
    column: int
    range: str
    row_label: str
    column_label: str
    function_cell: tuple[int, int] | None
    attributes: dict[str, str]


def _template(folder: Path) -> Path:
    """Generate the calculator's template into `folder` with its own code (no download)."""
    with extra("ncap2026"):
        from euroncap_rating_2026.crash_avoidance.generate_template import generate_template
    cwd = Path.cwd()
    try:
        os.chdir(folder)
        with contextlib.redirect_stdout(io.StringIO()):
            generate_template.callback()
    finally:
        os.chdir(cwd)
    return folder / "ca_template.xlsx"


def _labels(scenario: str, attributes: Mapping[str, str], choice: bool) -> tuple[str, str]:
    """The (row, column) labels `assess_2026` gives the same cell (assessment._labels)."""
    vut = attributes.get("VUT speed", "").strip()
    row = next((attributes[k].strip() for k in ("d", "Gap", "Distance") if k in attributes), None)
    if row is None:
        row = "SfS" if vut in ("", "SfS") else f"{float(vut.split()[0]):g} km/h"
    parts = [row]
    if scenario.startswith(("CPTA", "CBTA")) and "Turn" in attributes:
        parts.append(attributes["Turn"].strip().lower())
    if choice:
        parts.append("FCW")
    if t.COLUMN_AXIS.get(scenario) == "target_speed":
        column = f"{float(attributes['Target speed'].split()[0]):g} km/h"
    else:
        column = attributes["Impact location"]
    return " ".join(parts), column


def template_cells(template: Path | None = None) -> list[TemplateCell]:
    """Every VRU grid cell of the calculator's template, read with the calculator's own matrix code."""
    with extra("ncap2026"):
        from euroncap_rating_2026 import common
        from euroncap_rating_2026.crash_avoidance import data_model, matrix_processing
    with tempfile.TemporaryDirectory() as folder:
        path = template or _template(Path(folder))
        dfs = common.read_excel_file_to_dfs(str(path))
    cells = []
    for scenario, sheet in SHEETS.items():
        if scenario in NOT_PREDICTED:
            continue
        key = data_model.StageSubelementKey.LSC if sheet.startswith("LSC") else data_model.StageSubelementKey.FC
        frame = dfs[sheet]
        where = matrix_processing.get_matrix_indices(frame, scenario, data_model.MATRIX_INDICES)
        for point in matrix_processing.get_test_matrix(frame, scenario, key):
            choice = scenario in t.FCW_SCENARIOS and matrix_processing.is_fcw_declared_as_aeb(point, scenario)
            row_label, column_label = _labels(scenario, point.attributes, choice)
            sheet_row = where["start_row"] + point.row + 2
            cells.append(
                TemplateCell(
                    scenario=scenario,
                    sheet=sheet,
                    row=sheet_row,
                    column=where["start_col"] + point.col + 1,
                    range=point.test_range.value.lower(),
                    row_label=row_label,
                    column_label=column_label,
                    function_cell=(sheet_row, 3) if choice else None,
                    attributes={k: str(v).strip() for k, v in point.attributes.items()},
                )
            )
    return cells


def _fill(book: Any, assessment: Assessment2026, method: str, cells: list[TemplateCell]) -> list[str]:
    """Write colours, FCW/AEB choices, prediction methods and robustness cells into an openpyxl workbook;
    return the assessed cells that have no place in the template."""
    colours = {
        (c.scenario, c.row_label, c.column_label): c
        for c in assessment.cells
        if c.range != "robustness" and c.scenario not in NOT_PREDICTED
    }
    placed = set()
    for cell in cells:
        key = (cell.scenario, cell.row_label, cell.column_label)
        result = colours.get(key)
        if result is None:
            continue
        placed.add(key)
        book[cell.sheet].cell(row=cell.row, column=cell.column).value = result.colour.capitalize()
        if cell.function_cell is not None:
            declared = "FCW" if result.criterion == t.WARNING else "AEB"
            book[cell.sheet].cell(*cell.function_cell).value = declared
    sheet = book[INPUT_SHEET]
    scenario = None
    for r in range(2, sheet.max_row + 1):
        scenario = sheet.cell(r, 5).value or scenario
        if scenario in VRU_INPUT_SCENARIOS and sheet.cell(r, 6).value in PREDICTION_INPUTS:
            sheet.cell(r, 7).value = method
    for name in ROBUSTNESS_SHEETS:
        layers = book[name]
        for validation in layers.data_validations.dataValidation:
            if not validation.formula1 or "YES" not in validation.formula1:
                continue
            for block in validation.sqref.ranges:
                for r in range(block.min_row, block.max_row + 1):
                    for k in range(block.min_col, block.max_col + 1):
                        column = layers.cell(1, k).value
                        layer = layers.cell(r, 2).value
                        claimed = layer in assessment.robustness_claims.get(column, ())
                        layers.cell(r, k).value = "YES" if claimed else "NO"
    return sorted(f"{s} {r} / {k}" for s, r, k in set(colours) - placed)


def unpredicted_scenarios(assessment: Assessment2026, cells: list[TemplateCell] | None = None) -> list[str]:
    """The calculator's VRU scenarios with template cells the assessment leaves blank (a selection that is not the
    whole grid). The calculator still scores them: blank grids can earn their robustness points, so only a
    whole-grid file gives the points vrusim reports."""
    assessed = {(c.scenario, c.row_label, c.column_label) for c in assessment.cells}
    return sorted(
        {c.scenario for c in cells or template_cells() if (c.scenario, c.row_label, c.column_label) not in assessed}
    )


def write_predictions(assessment: Assessment2026, path: str | Path, method: str = "VTA") -> Path:
    """Fill the calculator's template with the assessment's colours and write it atomically to `path`.

    `method`: how the predictions were made, "VTA" (Virtual Testing) or "Self claimed" (FC26 §4.1, §5.3.4).
    A cell of the assessment the template has no place for is a UserInputError (nothing is written).
    """
    if method not in t.PREDICTION_METHODS:
        raise UserInputError(f"method: expected one of {', '.join(t.PREDICTION_METHODS)}, got {method!r}")
    with extra("ncap2026"):
        import openpyxl
    with tempfile.TemporaryDirectory() as folder:
        template = _template(Path(folder))
        cells = template_cells(template)
        book = openpyxl.load_workbook(template)
        missing = _fill(book, assessment, method, cells)
        if missing:
            raise UserInputError(f"assessment: cells not in the 2026 template: {', '.join(missing[:5])}")
        return write_atomically(path, lambda temp: book.save(temp), "2026 predictions")


def official_scores(path: str | Path) -> dict[str, dict[str, float]]:
    """Run the calculator's `preprocess` then `compute-score` (its CLI, in a temporary folder) on a predictions
    file; return {"scenarios": {calculator scenario group: points}, "sub_elements": {name: points}}."""
    with extra("ncap2026"):
        import pandas as pd
    with tempfile.TemporaryDirectory() as folder:
        work = Path(folder)
        shutil.copy(path, work / "input.xlsx")
        for args in (["preprocess", "-i", "input.xlsx"], ["compute-score", "-i", "ca_preprocessed_template.xlsx"]):
            command = [sys.executable, "-m", "euroncap_rating_2026", "crash_avoidance", *args, "-o", "."]
            done = subprocess.run(command, cwd=work, capture_output=True, text=True, check=False)
            if done.returncode != 0:
                said = (done.stdout + done.stderr).strip()[-400:]
                raise UserInputError(f"euroncap_rating_2026 {args[0]} failed: {said}")
        report = next(p for p in work.glob("ca_*_report.xlsx"))
        scenario_frame = pd.read_excel(report, sheet_name="Scenario Scores").ffill()
        stage_frame = pd.read_excel(report, sheet_name="Test Scores").ffill()
    scenarios = scenario_frame.groupby("Scenario")["Score"].sum().to_dict()
    sub_elements = {
        name: float(
            stage_frame[(stage_frame["Stage element"] == element) & (stage_frame["Stage subelement"] == sub)][
                "Score"
            ].iloc[0]
        )
        for name, (element, sub) in SUB_ELEMENT_ROWS.items()
    }
    return {"scenarios": {k: float(v) for k, v in scenarios.items()}, "sub_elements": sub_elements}


def grouped_points(assessment: Assessment2026) -> dict[str, float]:
    """vrusim's scenario points grouped as the calculator's "Scenario Scores" sheet groups them."""
    groups: dict[str, float] = {}
    for name, points in assessment.scenarios.items():
        group = SCORE_GROUPS.get(name, name)
        groups[group] = groups.get(group, 0.0) + points.total
    return groups
