"""The 2026 tables (FC26 / LSC26) against the official calculator and the protocol texts.

The grids — cells, speeds, impact locations, target speeds, FCW rows and standard / extended tags — must
equal the official calculator's, read with the calculator's own parser from its packaged template; protocol
values are checked against literal excerpts of the texts; every scenario the builder supports builds and,
without a reaction (planner `none`), makes contact in every cell.
"""

from __future__ import annotations

import functools
import re
from collections import Counter

import pytest

from vrusim.ncap.build import NcapTest
from vrusim.ncap.build_low_speed import LOW_SPEED_LAYOUTS
from vrusim.ncap.editions import edition
from vrusim.ncap.editions.lsc26 import CBDA_DOOR_OPERATION_M, CMCSCP_SFS_START_M, CPMRCM_TARGET_START_M
from vrusim.ncap.editions.robustness26 import FAMILIES, VERIFICATION_CONDITIONS, applicable_layers
from vrusim.ncap.editions.v2026 import SCENARIOS
from vrusim.ncap.grid import run_tests, select
from vrusim.ncap.protocol import DUMMIES, OBSTRUCTION_CARS, OBSTRUCTIONS, TURN_PATHS

BUILDER_LAYOUTS = {"crossing", "longitudinal", "turning", "reverse", "rear", "oncoming"} | set(LOW_SPEED_LAYOUTS)
"""Layouts `ncap/build.py` supports today."""

# ------------------------------------------------------------------------------------ the calculator's grids


def _calculator_points() -> dict[str, list[dict]]:
    """Every VRU test point of the calculator's template, by official scenario name, parsed by the
    calculator itself (attributes and standard / extended range)."""
    from importlib.resources import files

    from euroncap_rating_2026 import common
    from euroncap_rating_2026.crash_avoidance import data_model
    from euroncap_rating_2026.crash_avoidance import matrix_processing as mp

    path = str(files("data").joinpath("ca_template.xlsx"))
    dfs = common.read_excel_file_to_dfs(path, preserve_na_sheets=data_model.PRESERVE_NA_SHEETS)
    wanted = {spec.official.format(lighting=light) for spec in SCENARIOS for light in spec.lighting}
    points: dict[str, list[dict]] = {}
    for key, sub, sheet in (
        ("FC", "Ped & Cyc", "FC - Ped & Cyc pred."),
        ("FC", "Car & PTW", "FC - Car & PTW pred."),
        ("LSC", "Ped & Cyc", "LSC - Ped & Cyc pred."),
        ("LSC", "Car & PTW", "LSC - Car & PTW pred."),
    ):
        for name in data_model.STAGE_SUBELEMENT_TO_LOADCASES[key][sub]:
            if name not in wanted:
                continue
            stage = data_model.StageSubelementKey[key]
            for p in mp.get_test_matrix(dfs[sheet], name, stage):
                points.setdefault(name, []).append(_canonical_calculator(name, p))
    return points


def _kph(text: str) -> float:
    return float(text.replace("km/h", "").strip())


def _canonical_calculator(name: str, point) -> dict:
    """One calculator test point as comparable fields: vut, target, il (%), gap (m), distance, turn,
    direction, function, range. Only the fields the calculator's matrix carries."""
    out = {"range": point.test_range.value.lower()}
    for key, raw in point.attributes.items():
        value = str(raw).strip()
        if key == "VUT speed":
            out["vut"] = value if value == "SfS" else _kph(value)
        elif key == "Impact location":
            out["il"] = int(value.rstrip("%"))
        elif key in ("Gap", "d"):
            out["gap"] = float(value.replace("m", ""))
        elif key == "Distance":
            out["distance"] = value
        elif key == "Turn":
            out["turn"] = value.lower()
        elif key == "Target direction":
            out["direction"] = value.lower()
        elif key == "Function":
            out["function"] = value
        elif key == "Target speed" or value.endswith("km/h"):
            out["target"] = _kph(value)
    if name in ("CPLA day", "CPLA night", "CBLA", "CMRs") and "function" not in out:
        out["function"] = "FCW"  # the calculator's grey 'choice' rows are FC26's FCW rows
    return out


def _canonical_ours(test: NcapTest) -> dict:
    spec, cell = test.spec, test.cell
    distance = re.match(r"(d[12])-", cell.variant)
    return {
        "range": cell.range,
        "vut": "SfS" if spec.layout == "standstill_start" else cell.vut_speed_kph,
        "il": round(100 * test.impact_location),
        "gap": cell.gap_m,
        "distance": distance.group(1) if distance else None,
        "turn": spec.turn,
        "direction": "same" if spec.moves_with_vut and spec.layout == "turning" else "opposite",
        "function": cell.function or ("AEB" if spec.function != "FCW" else "FCW"),
        "target": round(test.target_speed_mps * 3.6, 6),
    }


def _every_test() -> list[NcapTest]:
    """Every cell of every 2026 table, day and night, including scenarios `select` leaves out (not yet built)."""
    return [
        NcapTest(spec, cell, lighting, "2026")
        for spec in SCENARIOS
        for lighting in spec.lighting
        for cell in spec.cells
    ]


def _ours() -> dict[str, list[NcapTest]]:
    tests: dict[str, list[NcapTest]] = {}
    for test in _every_test():
        tests.setdefault(test.spec.official.format(lighting=test.lighting), []).append(test)
    return tests


CALCULATOR = _calculator_points()
OURS = _ours()


def test_every_official_vru_scenario_is_encoded():
    assert set(OURS) == set(CALCULATOR)
    assert len(OURS) == 27  # 16 FC ped & cyc + 4 FC PTW + 5 LSC ped & cyc + 2 LSC PTW


@pytest.mark.parametrize("official", sorted(CALCULATOR))
def test_grid_equals_the_official_calculator(official):
    theirs = CALCULATOR[official]
    keys = set().union(*theirs)
    ours = [{k: v for k, v in _canonical_ours(t).items() if k in keys} for t in OURS[official]]
    as_set = lambda rows: Counter(tuple(sorted(r.items())) for r in rows)  # noqa: E731
    assert as_set(ours) == as_set(theirs), official


def test_cell_counts():
    counts = Counter((t.cell.range, t.lighting) for tests in OURS.values() for t in tests)
    assert counts == {
        ("standard", "day"): 224,
        ("extended", "day"): 294,
        ("standard", "night"): 40,
        ("extended", "night"): 78,
    }
    # hand count, FC26 §3.2: CPLA 10 rows × 4 IL, CPNA / CPFA 6 × 5, CPNCO 6 × 3, all day and night
    assert sum(counts[r, "night"] for r in ("standard", "extended")) == 40 + 30 + 30 + 18


def test_a_calculator_disagreement_is_caught():
    """The comparison fails if one tag is flipped (the test can fail)."""
    tests = OURS["CPNA day"]
    ours = [_canonical_ours(t) for t in tests]
    ours[0] = {**ours[0], "range": "standard" if ours[0]["range"] == "extended" else "extended"}
    keys = set().union(*CALCULATOR["CPNA day"])
    as_set = lambda rows: Counter(tuple(sorted((k, v) for k, v in r.items() if k in keys)) for r in rows)  # noqa: E731
    assert as_set(ours) != as_set(CALCULATOR["CPNA day"])


def test_test_ids_are_unique():
    ids = [t.test_id for t in _every_test()]
    assert len(ids) == len(set(ids)) == 636
    assert "CPLA/50kph/IL25/day" in ids and "CPLA/50kph/FCW-IL25/day" in ids


def test_lighting_night_only_where_the_protocol_has_night_tables():
    night = {s.code for s in SCENARIOS if "night" in s.lighting}
    assert night == {"CPLA", "CPNA", "CPFA", "CPNCO"}
    assert not any(s.extension for s in SCENARIOS)


# ------------------------------------------------------------------------------------ protocol text checks

FC26_TURN_TABLE = (
    "<td>15 km/h to Farside</td><td>1500</td><td>11.75</td><td>20.93</td><td>11.75</td><td>11.75</td>"
    "<td>48.14</td><td>11.75</td><td>1500</td><td>20.93</td></tr><tr><td>20 and 25 km/h to Farside</td>"
    "<td>1500</td><td>14.75</td><td>21.79</td><td>14.75</td><td>14.75</td><td>46.42</td>"
)
"""FC26 §1.2.4 (excerpt)."""


def test_turn_paths_follow_fc26():
    for speed in (20.0, 25.0):
        path = TURN_PATHS["farside", speed]
        assert (path.entry_radius_m, path.radius_m, path.clothoid_angle_deg, path.arc_angle_deg) == (
            1500.0, 14.75, 21.79, 46.42,
        )  # fmt: skip
    assert "<td>20 and 25 km/h to Farside</td><td>1500</td><td>14.75</td><td>21.79</td>" in FC26_TURN_TABLE
    turning = {(s.turn, c.vut_speed_kph) for s in SCENARIOS if s.layout in ("turning", "oncoming") for c in s.cells}
    assert turning <= set(TURN_PATHS)


FC26_CBTA = (
    "In all cases, the target speed is $1 5 \\mathrm { k m / h }$ and the target reference point is on the "
    "front wheel. [...] The EBT will follow a straight-line path which will be respectively 2.75m (CBTAfo) and "
    "$5 . 0 0 \\mathsf { m }$ (CBTAfs, CBTAns, CBTAno) from the centre of the centre dashed lane marking"
)
"""FC26 §3.2.2.2 (excerpt)."""


def test_cbta_geometry_follows_fc26():
    book = edition("2026")
    assert "2.75m (CBTAfo)" in FC26_CBTA and "(CBTAfs, CBTAns, CBTAno)" in FC26_CBTA
    assert book.scenario("CBTAfo").target_line_m == 2.75
    for code in ("CBTAfs", "CBTAns", "CBTAno"):
        assert book.scenario(code).target_line_m == 5.0
        assert book.scenario(code).target_speed_kph == 15.0
    assert book.scenario("CBTAfs").impact_side == "left" and book.scenario("CBTAns").impact_side == "right"


FC26_CMRB = (
    "For CMRb, the Time Headway $= 1 . 0 \\ s$ , and the target acceleration "
    "$= - 4 \\mathsf { m } / \\mathsf { s } ^ { 2 }$"
)
FC26_CMCSCP = (
    "the reference point of the EMT collides with $90 \\%$ side impact location [...] The group of 3 "
    "obstruction vehicles are parked 1m apart from each other, and at a lateral offset of 2m for nearside "
    "target approach"
)
FC26_CMFTAP = "The straight-line path of the VUT and target will be 1.75m from the centre of the centre dashed"
FC26_TARGET_SPEEDS = {  # FC26 §3.2 tables: the EPT / EBT speed column of each grid
    "CPNA": "<td>10 km/h</td><td>5 km/h</td><td>*</td>",
    "CPFA": "<td>10 km/h</td><td>8 km/h</td><td>*</td>",
    "CPNCO": "<td>10 km/h</td><td>5 km/h</td><td>*</td>",
    "CBNA": "<td>10 km/h</td><td>15 km/h</td>",
    "CBNAO": "<td>10 km/h</td><td>10 km/h</td>",
    "CBFA": "<td>10 km/h</td><td>20 km/h</td>",
    "CBLA": "<td>20 km/h</td><td>15 km/h</td><td>AEB</td>",
    "CBLA-FCW": "<td>50 km/h</td><td>20 km/h</td><td>FCW</td>",
}


def test_motorcyclist_values_follow_fc26():
    book = edition("2026")
    cmrb = book.scenario("CMRb")
    assert "Time Headway $= 1 . 0 \\ s$" in FC26_CMRB and "= - 4" in FC26_CMRB
    assert (cmrb.headway_s, cmrb.target_decel_mps2) == (1.0, 4.0)
    for code in ("CMCscp", "CMCscp-ext"):
        assert book.scenario(code).impact_location == 0.9 and "$90 \\%$ side impact" in FC26_CMCSCP
    row = OBSTRUCTIONS["CMCscp"]
    assert len(row.cars) == 3 and row.gap_m == 1.0 and "parked 1m apart" in FC26_CMCSCP
    assert row.cars[0] == "SUV"  # "Front obscuration vehicle (closest to target trajectory)": the larger one
    from vrusim.ncap.build import VUT

    assert row.clearance_m + VUT["width_m"] / 2 == pytest.approx(2.0)  # "lateral offset of 2m"
    assert book.scenario("CMCscp").obstruction == "CMCscp" and book.scenario("CMCscp-ext").obstruction is None
    assert "1.75m" in FC26_CMFTAP and book.scenario("CMFtap").target_line_m == 1.75


@pytest.mark.parametrize("code", sorted(FC26_TARGET_SPEEDS))
def test_target_speeds_follow_fc26(code):
    speed = float(re.findall(r"<td>([\d.]+) km/h</td>", FC26_TARGET_SPEEDS[code])[1])
    speeds = {round(t.target_speed_mps * 3.6, 9) for t in select([code], protocol="2026") if t.spec.code == code}
    assert speeds == {speed}


LSC26_TEXT = {
    "cmcscp": "The VUT is initially at standstill with an randomly selected longitudinal distance to the impact "
    "point of $_ { 2 . 9 \\mathsf { m } }$",
    "cpmrcm": "The EPTc is initially positioned 10.00m away from the centre of the VUT trajectory.",
    "cbda": "<tr><td>10</td><td>5.5 + [0.4]</td></tr><tr><td>15</td><td>8 + [0.5]</td></tr><tr><td>20</td>"
    "<td>11 + [0.7]</td></tr>",
}
"""LSC26 §3.1.2, §3.2.2.1, §3.2.3 (excerpts)."""


def test_low_speed_values_follow_lsc26():
    assert "2 . 9" in LSC26_TEXT["cmcscp"] and CMCSCP_SFS_START_M == 2.9
    assert "10.00m" in LSC26_TEXT["cpmrcm"] and CPMRCM_TARGET_START_M == 10.0
    rows = re.findall(r"<td>(\d+)</td><td>([\d.]+) \+ \[([\d.]+)\]</td>", LSC26_TEXT["cbda"])
    assert {float(s): (float(d), float(t)) for s, d, t in rows} == CBDA_DOOR_OPERATION_M


def test_obstruction_cars_inside_fc26_appendix_b():
    # B.1 smaller: length 4100-4400 mm, width 1700-1900 mm; B.2 larger: 4300-4700 mm, 1750-1900 mm
    assert 4.1 <= OBSTRUCTION_CARS["small car"][0] <= 4.4 and 1.7 <= OBSTRUCTION_CARS["small car"][1] <= 1.9
    assert 4.3 <= OBSTRUCTION_CARS["SUV"][0] <= 4.7 and 1.75 <= OBSTRUCTION_CARS["SUV"][1] <= 1.9


def test_every_target_and_obstruction_exists():
    for spec in SCENARIOS:
        assert spec.target in DUMMIES
        assert spec.obstruction is None or spec.obstruction in OBSTRUCTIONS


# ------------------------------------------------------------------------------------ robustness layers

APPENDIX_A_TOTALS = {
    "CMRs": 8, "CMRb": 9, "CMFtap": 8, "CMCscp": 8,
    "CPLA": 7, "CPTA": 9, "CPNA": 10, "CPFA": 10, "CPNCO": 10,
    "CBLA": 7, "CBTA": 9, "CBNA": 10, "CBFA": 10, "CBNAO": 10,
}  # fmt: skip
"""FC26 Appendix A, 'Total applicable Robustness Layers' rows."""


@pytest.mark.parametrize("family", FAMILIES)
def test_robustness_layers_match_appendix_a(family):
    layers = applicable_layers(family)
    assert len(layers) == APPENDIX_A_TOTALS[family]
    for layer in layers:
        if layer.assessment == "Verification Test" and layer.name != "Driver input pre-crash":
            assert (layer.name, family) in VERIFICATION_CONDITIONS, (layer.name, family)


# ------------------------------------------------------------------------------------ building and contact


def _buildable() -> list[str]:
    return [s.code for s in SCENARIOS if s.layout in BUILDER_LAYOUTS]


@functools.cache
def _grid_rows() -> list[dict]:
    """The whole buildable 2026 grid, day and night, without a function: one batch."""
    return run_tests(select(night=True, protocol="2026"), planner="none").rows


@pytest.mark.parametrize("code", _buildable())
def test_builder_supported_scenarios_make_contact_in_every_cell(code):
    tests = [t for t in select([code], night=True, protocol="2026") if t.spec.code == code]
    rows = [row for row in _grid_rows() if row["scenario"] == code]
    assert [row["test_id"] for row in rows] == [t.test_id for t in tests]
    missed = [r["test_id"] for r in rows if not r["collided"]]
    assert not missed, missed
    assert {r["protocol"] for r in rows} == {"2026"}
    assert all(r["official_scenario"] == tests[0].spec.official.format(lighting=r["lighting"]) for r in rows)
