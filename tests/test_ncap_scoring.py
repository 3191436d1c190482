"""Euro NCAP scoring: band edges, outcomes, FCW rule, point split, aggregation, files and the scorecard."""

from __future__ import annotations

import math
import os
import re
from pathlib import Path

import pyarrow.csv as pa_csv
import pyarrow.parquet as pq
import pytest
from hypothesis import given
from hypothesis import strategies as st
from matplotlib.image import imread
from rich.console import Console

import vrusim.ncap.assess as ncap
from vrusim.errors import UserInputError
from vrusim.ncap.assess import (
    SCHEMA,
    assess,
    assess_test,
    assessed_rows,
    band_colour,
    bands_row_speed_kph,
    capped,
    write_assessed_rows,
)
from vrusim.ncap.scoring import (
    BANDS_KPH,
    COLOURS,
    EURO_NCAP_GROUPS,
    FCW_FALLBACK_LABEL,
    GROUP_CAPS,
    POINTS_ENTRIES,
    SCENARIO_POINTS,
    SUB_SCORES,
)
from vrusim.viz.scorecard import scorecard_figure, write_scorecard_png
from vrusim.viz.scorecard_terminal import scorecard_renderables

DOCS = Path(__file__).resolve().parents[1] / "docs" / "euroncap_scoring.md"


def row(
    scenario="CPNA-25",
    group="pedestrian",
    function="AEB",
    lighting="day",
    speed_kph=50.0,
    impact_kph: float | None = None,
    target_kph: float | None = 0.0,
    warning_ttc_s: float | None = None,
    planner_warns=False,
    variant="",
) -> dict:
    """A catalogue result row; `impact_kph` None means no contact."""
    collided = impact_kph is not None
    return {
        "test_id": f"{scenario}/{speed_kph:g}kph/{lighting}" + (f"/{variant}" if variant else ""),
        "scenario": scenario,
        "group": group,
        "function": function,
        "lighting": lighting,
        "vut_speed_kph": speed_kph,
        "variant": variant,
        "collided": collided,
        "impact_speed_mps": impact_kph / 3.6 if collided else None,
        "target_longitudinal_speed_mps": target_kph / 3.6 if collided and target_kph is not None else None,
        "warning_ttc_s": warning_ttc_s,
        "planner_warns": planner_warns,
    }


# ----------------------------------------------------------------------------------------------- bands


@pytest.mark.parametrize(
    ("speed_kph", "relative_kph", "colour"),
    [
        (50.0, 0.0, "green"),
        (50.0, 10.0, "yellow"),
        (50.0, 10.01, "orange"),
        (50.0, 20.0, "orange"),
        (50.0, 30.0, "brown"),
        (50.0, 30.01, "red"),
        (80.0, 25.0, "brown"),
        (40.0, 10.0, "orange"),
        (40.0, 20.0, "brown"),
        (40.0, 20.01, "red"),
        (30.0, 10.0, "brown"),
        (30.0, 10.1, "red"),
        (20.0, 0.01, "red"),
        (10.0, 0.0, "green"),
        # 5 km/h grid between table rows: the row of the largest tabulated speed <= the test speed
        (15.0, 5.0, "red"),  # 10 row (green / red only)
        (25.0, 5.0, "red"),  # 20 row, not the 30 row (which would give brown)
        (35.0, 5.0, "brown"),  # 30 row, not the 40 row (orange)
        (45.0, 5.0, "orange"),  # 40 row, not the 50 row (yellow)
        (45.0, 20.0, "brown"),
    ],
)
def test_band_edges_through_assess_test(speed_kph, relative_kph, colour):
    test = assess_test(row(speed_kph=speed_kph, impact_kph=relative_kph))
    assert test.relative_impact_speed_kph == relative_kph
    assert test.colour == colour
    assert test.sub_score == SUB_SCORES[colour]


@pytest.mark.parametrize(("speed", "row_speed"), [(4, None), (8, None), (10, 10), (15, 10), (45, 40), (130, 50)])
def test_band_row_is_largest_tabulated_speed_not_above(speed, row_speed):
    assert bands_row_speed_kph(speed) == row_speed


@given(
    speed=st.floats(0.0, 130.0),
    a=st.floats(0.0, 200.0),
    b=st.floats(0.0, 200.0),
)
def test_sub_score_never_increases_with_relative_impact_speed(speed, a, b):
    low, high = sorted((a, b))
    assert SUB_SCORES[band_colour(speed, low)] >= SUB_SCORES[band_colour(speed, high)]


@given(
    speed=st.sampled_from([4.0, 8.0, *range(10, 135, 5)]),
    fraction=st.floats(0.0, 1.0),
    target=st.one_of(st.none(), st.floats(-50.0, 50.0)),
    function=st.sampled_from(["AEB", "FCW", "avoidance"]),
    warns=st.booleans(),
    ttc=st.one_of(st.none(), st.floats(0.0, 10.0)),
)
def test_assessed_values_are_finite_and_consistent(speed, fraction, target, function, warns, ttc):
    test = assess_test(
        row(speed_kph=speed, impact_kph=fraction * speed, target_kph=target, function=function)
        | {"planner_warns": warns, "warning_ttc_s": ttc}
    )
    numbers = [test.relative_impact_speed_kph, test.speed_reduction_kph, test.sub_score, test.impact_speed_kph]
    assert all(isinstance(x, float) and math.isfinite(x) for x in numbers)
    assert test.relative_impact_speed_kph >= 0.0
    assert test.relative_impact_speed_kph <= test.impact_speed_kph
    assert 0.0 <= test.sub_score <= 1.0
    assert test.colour in COLOURS


# ----------------------------------------------------------------------------------------------- per test


def test_longitudinal_target_speed_is_subtracted():
    test = assess_test(row(scenario="CBLA-50", group="cyclist", speed_kph=40.0, impact_kph=30.0, target_kph=15.0))
    assert test.impact_speed_kph == 30.0
    assert test.relative_impact_speed_kph == 15.0
    assert test.speed_reduction_kph == 10.0
    assert test.colour == "brown"  # 40 row: 10 < 15 <= 20
    assert test.outcome == "mitigated"


def test_oncoming_target_counts_as_zero_and_relative_never_negative():
    oncoming = assess_test(row(speed_kph=50.0, impact_kph=20.0, target_kph=-10.0))
    assert oncoming.relative_impact_speed_kph == 20.0
    slower = assess_test(row(scenario="CBLA-50", group="cyclist", speed_kph=40.0, impact_kph=12.0, target_kph=15.0))
    assert slower.relative_impact_speed_kph == 0.0
    assert slower.colour == "green"


def test_avoided_is_green_with_full_speed_reduction():
    test = assess_test(row(speed_kph=35.0))
    assert (test.outcome, test.colour, test.sub_score) == ("avoided", "green", 1.0)
    assert test.impact_speed_kph is None
    assert test.relative_impact_speed_kph == 0.0
    assert test.speed_reduction_kph == 35.0


@pytest.mark.parametrize(
    ("impact_kph", "outcome"), [(49.9, "mitigated"), (49.95, "not mitigated"), (50.0, "not mitigated")]
)
def test_mitigation_needs_a_tenth_of_a_kph(impact_kph, outcome):
    assert assess_test(row(speed_kph=50.0, impact_kph=impact_kph)).outcome == outcome


def test_avoidance_only_scenarios_are_green_or_red():
    tap = {"scenario": "CMFtap", "group": "motorcyclist", "function": "avoidance", "variant": "EMT45"}
    assert assess_test(row(**tap, speed_kph=20.0)).colour == "green"
    hit = assess_test(row(**tap, speed_kph=20.0, impact_kph=1.0))
    assert (hit.colour, hit.criterion) == ("red", "avoidance only")
    # 50 km/h bands would make a 1 km/h impact yellow; avoidance-only makes it red
    assert assess_test(row(**tap, speed_kph=50.0, impact_kph=1.0)).colour == "red"
    # touched after the VUT had stopped (V_impact = 0): allowed, green (FC26)
    stopped = assess_test(row(**tap, speed_kph=20.0, impact_kph=0.0))
    assert (stopped.collided, stopped.colour) == (True, "green")


@pytest.mark.parametrize("speed", [4.0, 8.0])
def test_reversing_speeds_are_avoidance_only(speed):
    cpra = {"scenario": "CPRA-Cs", "function": "AEB", "variant": "IL25-adult"}
    assert assess_test(row(**cpra, speed_kph=speed)).colour == "green"
    hit = assess_test(row(**cpra, speed_kph=speed, impact_kph=0.5))
    assert (hit.colour, hit.criterion) == ("red", "avoidance only")


@pytest.mark.parametrize(
    ("ttc", "impact_kph", "colour"),
    [(1.7, None, "green"), (1.7 - 1e-3, None, "red"), (None, None, "red"), (2.5, 40.0, "green"), (1.0, 5.0, "red")],
)
def test_fcw_judged_by_warning_ttc(ttc, impact_kph, colour):
    test = assess_test(
        row(scenario="CPLA-25", function="FCW", speed_kph=60.0, impact_kph=impact_kph, warning_ttc_s=ttc)
        | {"planner_warns": True}
    )
    assert (test.criterion, test.colour) == ("FCW warning TTC", colour)


def test_fcw_row_falls_back_to_aeb_bands_without_warnings():
    fcw = {"scenario": "CBLA-25", "group": "cyclist", "function": "FCW", "planner_warns": False}
    test = assess_test(row(**fcw, speed_kph=60.0, impact_kph=25.0, target_kph=20.0))
    assert test.criterion == FCW_FALLBACK_LABEL
    assert (test.relative_impact_speed_kph, test.colour) == (5.0, "yellow")
    assert assess_test(row(**fcw, speed_kph=80.0)).colour == "green"


def test_rows_that_do_not_fit_the_tables_are_refused():
    with pytest.raises(ValueError, match="no points"):
        assess_test(row(scenario="CPTAfs", lighting="night"))
    with pytest.raises(ValueError, match="belongs to cyclist"):
        assess_test(row(scenario="CBNA-50", group="pedestrian"))
    with pytest.raises(ValueError, match="function"):
        assess_test(row(function="LSS"))
    with pytest.raises(ValueError, match="impact speed"):
        assess_test(row(impact_kph=10.0) | {"impact_speed_mps": math.nan})


# ----------------------------------------------------------------------------------------------- points


def test_points_split_hand_computed():
    # weights: pedestrian sum 10.40625 (CPLA 2.25, CPTA 2.5, CPNA 1.125, CPFA 1.125, CPNCO 2.25, CPRA 1.15625)
    assert SCENARIO_POINTS[("CPNA-25", "day")] == pytest.approx(9 / 37)  # 0.5625 / 2 x 9 / 10.40625
    assert SCENARIO_POINTS[("CPRA-Cm", "day")] + SCENARIO_POINTS[("CPRA-Cs", "day")] == pytest.approx(1.0)
    assert SCENARIO_POINTS[("CPTAfs", "day")] == pytest.approx(2.5 * 3 / 8 * 9 / 10.40625)
    assert SCENARIO_POINTS[("CBNAO-50", "day")] == pytest.approx(2.5 * 8 / 9.75)
    assert SCENARIO_POINTS[("CBLA-50", "day")] == pytest.approx(2.25 * 8 / 15 * 8 / 9.75)
    assert SCENARIO_POINTS[("CMRs", "day")] == pytest.approx(1.5 * 5 / 8 * 6 / 8.5)
    assert SCENARIO_POINTS[("CMRs-FCW", "day")] == pytest.approx(1.5 * 3 / 8 * 6 / 8.5)
    assert SCENARIO_POINTS[("CMRb", "day")] == pytest.approx(2.0 * 6 / 8.5)
    assert SCENARIO_POINTS[("CMFtap", "day")] == pytest.approx(5.0 * 6 / 8.5)
    assert SCENARIO_POINTS[("CENA-50", "day")] == 1.0


def test_points_table_is_consistent():
    for group, cap in GROUP_CAPS.items():
        assert sum(p for k, p in SCENARIO_POINTS.items() if POINTS_ENTRIES[k].group == group) == pytest.approx(cap)
    families: dict[tuple[str, str], list] = {}
    for entry in POINTS_ENTRIES.values():
        families.setdefault((entry.family, entry.lighting), []).append(entry)
        if entry.group in EURO_NCAP_GROUPS:
            assert entry.unverified.startswith("UNVERIFIED: ")
        else:
            assert entry.unverified.startswith("EXTENSION: ")
    for members in families.values():
        assert sum(m.cells for m in members) == members[0].family_cells
        assert len({m.fc26_points for m in members}) == 1
    for _, bands in BANDS_KPH:
        bounds = [bound for bound, _ in bands]
        assert bounds == sorted(bounds) and bounds[0] == 0.0 and bounds[-1] == math.inf
        assert bands[0][1] == "green" and bands[-1][1] == "red"


def test_docs_list_every_points_entry():
    text = DOCS.read_text(encoding="utf-8")
    for (scenario, lighting), points in SCENARIO_POINTS.items():
        pattern = rf"^\| {re.escape(scenario)} \| {lighting} \|.*\| {points:.4f} \|"
        assert re.search(pattern, text, re.MULTILINE), (scenario, lighting, f"{points:.4f}")
    rows = re.findall(r"^\| (C[A-Za-z-]+\d*(?:-[A-Za-z]+)?) \| (day|night) \|", text, re.MULTILINE)
    assert sorted(set(rows)) == sorted(SCENARIO_POINTS)  # and nothing the code does not score


def test_points_table_matches_the_catalogue():
    """Cell counts and (scenario, lighting) pairs come from the protocol tables: every catalogue pair is
    scored and every scored pair exists in the catalogue."""
    from vrusim.ncap.scoring import BY_CODE, SCENARIOS

    catalogue = {(spec.code, lighting) for spec in SCENARIOS for lighting in spec.lighting}
    assert set(SCENARIO_POINTS) == catalogue
    for entry in POINTS_ENTRIES.values():
        assert entry.cells == len(BY_CODE[entry.scenario].cells), entry.scenario


# ----------------------------------------------------------------------------------------------- aggregation


def test_scenario_score_on_a_hand_made_grid():
    rows = [
        row(speed_kph=20.0),  # green 1
        row(speed_kph=50.0, impact_kph=5.0),  # yellow 0.75
        row(speed_kph=30.0, impact_kph=5.0),  # brown 0.25
        row(speed_kph=40.0, impact_kph=40.0),  # red 0
        row(speed_kph=30.0, lighting="night"),  # other key: green 1
    ]
    result = assess(rows)
    scores = {(s.scenario, s.lighting): s for s in result.group("pedestrian").scenarios}
    day = scores[("CPNA-25", "day")]
    assert (day.cells, day.sub_score_sum) == (4, 2.0)
    assert day.score == pytest.approx(2.0 * (9 / 37) / 4)
    assert scores[("CPNA-25", "night")].score == pytest.approx(9 / 37)
    assert result.group("pedestrian").score == pytest.approx(1.5 * 9 / 37)
    assert result.total == pytest.approx(1.5 * 9 / 37)
    assert result.total_max == 23.0
    assert "CPNA-75/day" in result.group("pedestrian").not_assessed


def test_full_marks_reach_every_cap_and_23_in_total():
    rows = [
        row(scenario=s, group=POINTS_ENTRIES[(s, light)].group, lighting=light, speed_kph=30.0)
        for s, light in POINTS_ENTRIES
    ]
    result = assess(rows)
    for group, cap in GROUP_CAPS.items():
        assert result.group(group).score == pytest.approx(cap)
    assert result.total == pytest.approx(23.0)


def test_group_cap_clips():
    assert capped(9.5, 9.0) == 9.0
    assert capped(8.25, 9.0) == 8.25
    assert capped(12.0, None) == 12.0


def test_group_score_is_clipped_to_its_cap(monkeypatch):
    monkeypatch.setitem(ncap.SCENARIO_POINTS, ("CMFtap", "day"), 10.0)
    result = assess([row(scenario="CMFtap", group="motorcyclist", function="avoidance", speed_kph=10.0)])
    motorcyclist = result.group("motorcyclist")
    assert (motorcyclist.raw_sum, motorcyclist.score) == (10.0, 6.0)
    assert result.total == 6.0


def test_escooter_extension_is_outside_the_total():
    escooter = [row(scenario=s, group="escooter", speed_kph=30.0) for s in ("CENA-50", "CEFA-50")]
    pedestrian = [row(speed_kph=30.0)]
    alone = assess(escooter)
    assert alone.total == 0.0 and alone.total_max == 23.0
    group = alone.group("escooter")
    assert (group.score, group.max_points, group.cap, group.in_euro_ncap_total) == (2.0, 2.0, None, False)
    assert assess(escooter + pedestrian).total == assess(pedestrian).total == pytest.approx(9 / 37)


def test_assessment_is_json_ready():
    import json

    document = assess([row(speed_kph=30.0, impact_kph=12.0), row(speed_kph=50.0)]).to_dict()
    json.dumps(document, allow_nan=False)
    assert document["tests"][1]["impact_speed_kph"] is None


# ----------------------------------------------------------------------------------------------- files


def _sample_tests():
    return assess(
        [
            row(speed_kph=30.0, impact_kph=12.0),
            row(speed_kph=50.0),
            row(scenario="CPLA-25", function="FCW", speed_kph=60.0, warning_ttc_s=2.0) | {"planner_warns": True},
            row(scenario="CPRA-Cs", speed_kph=4.0, variant="IL25-adult"),
        ]
    ).tests


def test_csv_and_parquet_round_trip(tmp_path):
    tests = _sample_tests()
    expected = assessed_rows(tests)
    assert write_assessed_rows(tests, tmp_path / "a.csv") == len(tests)
    write_assessed_rows(tests, tmp_path / "a.parquet")
    parquet = pq.read_table(tmp_path / "a.parquet")
    assert parquet.schema.equals(SCHEMA)
    assert parquet.to_pylist() == expected
    csv = pa_csv.read_csv(tmp_path / "a.csv", convert_options=pa_csv.ConvertOptions(column_types=SCHEMA))
    assert csv.select(SCHEMA.names).to_pylist() == expected
    assert sorted(os.listdir(tmp_path)) == ["a.csv", "a.parquet"]


def test_failed_writes_leave_no_file(tmp_path, monkeypatch):
    tests = _sample_tests()
    with pytest.raises(UserInputError, match="missing"):
        write_assessed_rows(tests, tmp_path / "missing" / "a.csv")
    with pytest.raises(UserInputError, match="unsupported"):
        write_assessed_rows(tests, tmp_path / "a.json")
    assert not (tmp_path / "missing").exists()

    # a writer that fails half-way: the old file stays intact, no temporary file is left
    target = tmp_path / "a.parquet"
    target.write_bytes(b"old")

    def broken(table, where):
        Path(where).write_bytes(b"PAR1 half")
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(ncap.pq, "write_table", broken)
    with pytest.raises(UserInputError, match="No space left"):
        write_assessed_rows(tests, target)
    assert target.read_bytes() == b"old"
    assert os.listdir(tmp_path) == ["a.parquet"]


def test_unwritable_folder_is_a_user_error(tmp_path, monkeypatch):
    """What a read-only folder does to a non-root user (root can write anywhere, so simulated here)."""
    import vrusim.io.atomic

    def refused(**kwargs):
        raise PermissionError(13, "Permission denied")

    monkeypatch.setattr(vrusim.io.atomic.tempfile, "mkstemp", refused)
    with pytest.raises(UserInputError, match="Permission denied"):
        write_assessed_rows(_sample_tests(), tmp_path / "a.csv")
    assert os.listdir(tmp_path) == []


@pytest.mark.skipif(os.name != "posix" or os.geteuid() == 0, reason="needs a non-root POSIX user")
def test_read_only_folder_leaves_no_file(tmp_path):
    folder = tmp_path / "ro"
    folder.mkdir()
    folder.chmod(0o555)
    try:
        with pytest.raises(UserInputError):
            write_assessed_rows(_sample_tests(), folder / "a.csv")
        with pytest.raises(UserInputError):
            write_scorecard_png(assess([row()]), folder / "card.png")
        assert os.listdir(folder) == []
    finally:
        folder.chmod(0o755)


# ----------------------------------------------------------------------------------------------- scorecard


def _known_assessment():
    return assess(
        [
            row(speed_kph=10.0),  # day 10: green
            row(speed_kph=20.0, impact_kph=15.0),  # day 20: red
            row(speed_kph=10.0, lighting="night", impact_kph=10.0),  # night 10: red
            row(speed_kph=20.0, lighting="night"),  # night 20: green
        ]
    )


def _cell_rgb(image, fig, ax, column, row_index):
    """Median colour of the central half of one heat-map cell in the written image."""
    x0, y0 = ax.transData.transform((column - 0.5, row_index - 0.5))
    x1, y1 = ax.transData.transform((column + 0.5, row_index + 0.5))
    height = image.shape[0]
    left, right = sorted((x0, x1))
    bottom, top = sorted((y0, y1))
    cx, cy, w, h = (left + right) / 2, (bottom + top) / 2, right - left, top - bottom
    assert w > 20 and h > 10  # the cell is big enough to sample
    rows = slice(int(height - (cy + h / 4)), int(height - (cy - h / 4)))
    cols = slice(int(cx - w / 4), int(cx + w / 4))
    patch = image[rows, cols, :3].reshape(-1, 3)
    return sorted(patch.tolist(), key=sum)[len(patch) // 2]


def test_png_cells_have_their_colours(tmp_path):
    assessment = _known_assessment()
    path = write_scorecard_png(assessment, tmp_path / "card.png", dpi=100)
    image = imread(path)
    fig = scorecard_figure(assessment, dpi=100)
    fig.canvas.draw()
    assert image.shape[1::-1] == fig.canvas.get_width_height()
    ax = fig.axes[0]
    assert ax.get_title(loc="left") == f"Pedestrian: {assessment.group('pedestrian').score:.2f} / 9 pts"
    green, red = _cell_rgb(image, fig, ax, 0, 0), _cell_rgb(image, fig, ax, 1, 0)
    night_red, night_green = _cell_rgb(image, fig, ax, 0, 1), _cell_rgb(image, fig, ax, 1, 1)
    for r, g, b in (green, night_green):
        assert g > 0.5 and g > r + 0.2 and g > b + 0.2
    for r, g, b in (red, night_red):
        assert r > 0.6 and r > g + 0.3 and r > b + 0.3
    assert os.listdir(tmp_path) == ["card.png"]


def test_png_write_failure_leaves_no_file(tmp_path, monkeypatch):
    with pytest.raises(UserInputError):
        write_scorecard_png(_known_assessment(), tmp_path / "missing" / "card.png")
    from matplotlib.figure import Figure

    def broken(self, where, **kwargs):
        Path(where).write_bytes(b"\x89PNG half")
        raise RuntimeError("renderer crashed")

    monkeypatch.setattr(Figure, "savefig", broken)
    with pytest.raises(RuntimeError):
        write_scorecard_png(_known_assessment(), tmp_path / "card.png")
    assert os.listdir(tmp_path) == []


def test_rich_scorecard_shows_groups_cells_and_totals():
    escooter = row(scenario="CENA-50", group="escooter", speed_kph=30.0)
    renderables = scorecard_renderables(assess([*_rows_for_rich(), escooter]))
    console = Console(record=True, width=160, color_system="truecolor")
    for item in renderables:
        console.print(item)
    text = console.export_text(clear=False)
    assert "Pedestrian: " in text and "/ 9 pts" in text
    assert "E-scooter" in text and "nominal pts" in text
    assert "✓" in text and " 15 " in text
    assert re.search(r"Total\s+0\.12\s+23", text)
    html = console.export_html(inline_styles=True)
    assert "background-color: #3aa845" in html and "background-color: #d62b2b" in html


def _rows_for_rich():
    return [row(speed_kph=10.0), row(speed_kph=20.0, impact_kph=15.0)]
