"""Predictions for the official 2026 calculator: the file passes its preprocess and compute-score, and vrusim's
points equal the calculator's on the same colours."""

from __future__ import annotations

import pytest

pytest.importorskip("euroncap_rating_2026")
openpyxl = pytest.importorskip("openpyxl")

from ncap2026_rows import rows_for, seeded  # noqa: E402
from vrusim.errors import UserInputError  # noqa: E402
from vrusim.ncap.predictions import grouped_points, official_scores, template_cells, write_predictions  # noqa: E402
from vrusim.ncap.rating2026 import assess_2026  # noqa: E402
from vrusim.ncap.rating2026 import tables as t  # noqa: E402


@pytest.fixture(scope="module")
def cells():
    return template_cells()


def test_template_cells_cover_every_vru_grid(cells):
    names = {c.scenario for c in cells}
    assert names == set(t.TOTAL_POINTS) - {"CBDA"}
    assert {c.range for c in cells} == {"standard", "extended"}
    assert len({(c.scenario, c.row_label, c.column_label) for c in cells}) == len(cells)


GRIDS = {
    "all-green": lambda cell, options: "green",
    "mixed-7": seeded(7),
}
"""Colour grids scored by both vrusim and the calculator (every planner warns: FCW rows judged by TTC), next to
vrusim's own whole-grid AEB assessment (its reds, below half of the standard points, exercise the robustness
floor). Each calculator run takes about 13 s: three in parallel keep the suite's budget."""


@pytest.fixture(scope="module")
def scored(cells, tmp_path_factory):
    """(vrusim's assessment, the calculator's scores) per grid; the calculator runs (about 13 s each, two
    subprocesses) go in parallel."""
    from concurrent.futures import ThreadPoolExecutor

    folder = tmp_path_factory.mktemp("predictions")
    claims = {"CPNA": ["Speed"], "CBNA": ["Type", "Speed"]}
    assessments = {name: assess_2026(rows_for(cells, pick, True), claims) for name, pick in GRIDS.items()}
    assessments["vrusim-aeb"] = _whole_grid_aeb()
    paths = {name: write_predictions(a, folder / f"{name}.xlsx") for name, a in assessments.items()}
    with ThreadPoolExecutor(max_workers=len(paths)) as pool:
        official = dict(zip(paths, pool.map(official_scores, paths.values()), strict=True))
    return {name: (assessments[name], official[name]) for name in assessments}


def _whole_grid_aeb():
    """vrusim's own assessment of the whole 2026 grid, day and night, AEB planner without V2X."""
    from vrusim.ncap.grid import select
    from vrusim.ncap.rated2026 import rate_2026

    return rate_2026(select(night=True, protocol="2026"), planner="aeb").assessment


@pytest.mark.parametrize("grid", [*GRIDS, "vrusim-aeb"])
def test_points_equal_the_official_calculator(scored, grid):
    assessment, official = scored[grid]
    ours = grouped_points(assessment)
    for name, points in ours.items():
        # the calculator prints points to 3 decimals per range
        assert official["scenarios"][name] == pytest.approx(points, abs=2e-3), name
    for name, points in assessment.sub_elements.items():
        assert official["sub_elements"][name] == pytest.approx(points, abs=5e-3), name


def test_a_partial_selection_names_the_scenarios_it_leaves_blank(cells, scored):
    from vrusim.ncap.predictions import unpredicted_scenarios

    assert unpredicted_scenarios(scored["vrusim-aeb"][0], cells) == []  # the whole grid predicts every scenario
    partial = assess_2026([row for row in rows_for(cells, seeded(3), True) if row["official_scenario"] == "CBNA"])
    blank = unpredicted_scenarios(partial, cells)
    assert "CBNA" not in blank and {"CPNA day", "CMRs", "CPMFC"} <= set(blank)


def test_written_cells_hold_colour_words(cells, tmp_path):
    assessment = assess_2026(rows_for(cells, seeded(3)))
    path = write_predictions(assessment, tmp_path / "p.xlsx")
    book = openpyxl.load_workbook(path)
    colours = {(c.scenario, c.row_label, c.column_label): c.colour for c in assessment.cells}
    for cell in cells[::17]:
        value = book[cell.sheet].cell(cell.row, cell.column).value
        assert value == colours[(cell.scenario, cell.row_label, cell.column_label)].capitalize()
    assert book["Input parameters"]["G32"].value == "VTA"  # CPNA Prediction - Standard


def test_robustness_sheet_columns_match_applicable_layers(tmp_path, cells):
    path = write_predictions(assess_2026(rows_for(cells[:3], seeded(1))), tmp_path / "r.xlsx")
    book = openpyxl.load_workbook(path)
    found: dict[str, list[str]] = {}
    for name in ("FC - Ped & Cyc robust. pred.", "FC - Car & PTW robust. pred."):
        sheet = book[name]
        for k in range(3, sheet.max_column + 1):
            column = sheet.cell(1, k).value
            found[column] = [sheet.cell(r, 2).value for r in range(2, sheet.max_row + 1) if sheet.cell(r, k).value]
    for column, layers in t.APPLICABLE_LAYERS.items():
        assert tuple(found[column]) == layers, column


def test_bad_method_and_unplaceable_cells_write_nothing(cells, tmp_path):
    assessment = assess_2026(rows_for(cells[:4], seeded(2)))
    with pytest.raises(UserInputError, match="method"):
        write_predictions(assessment, tmp_path / "x.xlsx", method="guess")
    odd = rows_for(cells[:1], seeded(2))
    odd[0]["impact_location"] = 0.33
    with pytest.raises(UserInputError, match="not in the 2026 template"):
        write_predictions(assess_2026(odd), tmp_path / "y.xlsx")
    with pytest.raises(UserInputError):
        write_predictions(assessment, tmp_path / "missing" / "z.xlsx")
    assert list(tmp_path.iterdir()) == []
