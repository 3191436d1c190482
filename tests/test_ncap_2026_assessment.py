"""The 2026 assessment: band edges (FC26 §4.2.4/§5.2), points (§5.3) hand-computed, tables vs the calculator."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from vrusim.errors import UserInputError
from vrusim.ncap.rating2026 import assess_2026
from vrusim.ncap.rating2026 import tables as t
from vrusim.ncap.rating2026.colours import KPH, accepted, taeb_s, vrel_colour
from vrusim.ncap.rating2026.points import fc_points


def row(scenario="CPNA day", vut=60.0, loc=0.5, rng="standard", vrel=None, **extra):
    base = {
        "test_id": f"{scenario}-{vut}-{loc}-{rng}",
        "protocol": "2026",
        "scenario": "CPNA",
        "official_scenario": scenario,
        "lighting": "day",
        "vut_speed_kph": vut,
        "impact_location": loc,
        "target_speed_kph": 5.0,
        "range": rng,
        "function": "AEB",
        "collided": vrel is not None,
        "impact_speed_mps": None if vrel is None else vrel * KPH,
        "target_longitudinal_speed_mps": 0.0,
        "warning_ttc_s": None,
        "planner_warns": False,
    }
    return {**base, **extra}


@pytest.mark.parametrize(
    ("vrel", "vut", "colour"),
    [
        (0.0, 60, "green"), (0.01, 60, "yellow"), (10.0, 60, "yellow"), (10.01, 60, "orange"), (20.0, 60, "orange"),
        (20.01, 60, "brown"), (30.0, 60, "brown"), (30.01, 60, "red"), (10.0, 50, "yellow"), (20.0, 40, "brown"),
        (20.01, 40, "red"), (5.0, 40, "orange"), (10.0, 30, "brown"), (10.01, 30, "red"), (0.01, 20, "red"),
        (0.01, 10, "red"), (0.0, 10, "green"), (25.0, 80, "brown"),
    ],
)  # fmt: skip
def test_vrel_bands_follow_fc26_table(vrel, vut, colour):
    # FC26 §4.2.4 (60 km/h): Yellow 0 < v <= 10, Orange 10 < v <= 20, Brown 20 < v <= 30, Red 30 < v
    assert vrel_colour(vrel, vut) == colour


@pytest.mark.parametrize(
    ("predicted", "vrel", "ok"),
    [
        ("green", 1.99, True), ("green", 2.0, False), ("yellow", 12.0, True), ("yellow", 12.01, False),
        ("orange", 8.0, True), ("orange", 8.01, True), ("orange", 22.0, True), ("orange", 22.01, False),
        ("brown", 18.0, True), ("brown", 18.01, True), ("brown", 32.0, True), ("brown", 32.01, False),
        ("brown", 0.0, True), ("yellow", 0.0, True),
    ],
)  # fmt: skip
def test_accepted_ranges_are_fc26_4_2_4_example(predicted, vrel, ok):
    # the accepted-range column of FC26 §4.2.4 for the 60 km/h test; better than predicted passes (§5.3.4)
    assert accepted(predicted, vrel, 60.0) is ok


def test_points_of_a_small_grid_by_hand():
    rows = [
        row(vut=60, loc=0.75, vrel=None),  # green 1.0
        row(vut=60, loc=0.5, vrel=5.0),  # yellow 0.75
        row(vut=60, loc=0.25, vrel=40.0),  # red 0
        row(vut=40, loc=0.5, vrel=5.0),  # orange 0.5
        row(vut=60, loc=0.9, rng="extended", vrel=25.0),  # brown: counts 1
        row(vut=50, loc=0.9, rng="extended", vrel=None),
        row(vut=40, loc=0.9, rng="extended", vrel=None),
        row(vut=30, loc=0.9, rng="extended", vrel=15.0),  # red
    ]
    a = assess_2026(rows)
    p = a.scenarios["CPNA day"]
    assert p.standard == pytest.approx((1 + 0.75 + 0 + 0.5) / 4 * 0.5)  # 0.28125
    assert p.extended == pytest.approx(0.75 * 0.0625)  # 3 of 4 non-red: 75 % step
    assert p.robustness == 0.0
    assert a.sub_elements["FC Pedestrian & Cyclist"] == pytest.approx(0.28125 + 0.046875)
    claimed = assess_2026(rows, {"CPNA": ["Speed", "Type"]})
    assert claimed.scenarios["CPNA day"].robustness == pytest.approx(0.125 / 10 * 2)  # 10 applicable layers
    low = assess_2026([r for r in rows if r["impact_location"] != 0.75], {"CPNA": ["Speed"]})
    assert low.scenarios["CPNA day"].standard < 0.25 and low.scenarios["CPNA day"].robustness == 0.0


@given(st.lists(st.sampled_from(t.COLOURS), min_size=1, max_size=30), st.lists(st.sampled_from(t.COLOURS), max_size=30))
def test_fc_points_formula(standard, extended):
    p = fc_points("CBNA", standard, extended)
    assert p.standard == pytest.approx(sum(t.STANDARD_SUB_SCORE[c] for c in standard) / len(standard) * 1.0)
    share = sum(c != "red" for c in extended) / len(extended) if extended else 0.0
    step = 1.0 if share >= 1 else 0.75 if share >= 0.75 else 0.5 if share >= 0.5 else 0.0
    assert p.extended == pytest.approx(step * 0.125)


def test_fcw_rows_by_warning_ttc_or_as_declared_aeb():
    fcw = dict(official_scenario="CPLA day", function="FCW", vut=70.0, loc=0.25)
    warn_ok = row(**{k: v for k, v in fcw.items() if k in ("vut", "loc")}, official_scenario="CPLA day",
                  function="FCW", planner_warns=True, warning_ttc_s=1.7, vrel=20.0)  # fmt: skip
    warn_late = dict(warn_ok, test_id="late", vut_speed_kph=80.0, warning_ttc_s=1.69)
    silent = dict(warn_ok, test_id="silent", vut_speed_kph=60.0, planner_warns=False, warning_ttc_s=None)
    a = assess_2026([warn_ok, warn_late, silent])
    colours = {c.test_id: (c.criterion, c.colour) for c in a.cells}
    assert colours[warn_ok["test_id"]] == (t.WARNING, "green")
    assert colours["late"] == (t.WARNING, "red")
    assert colours["silent"] == (t.AVOIDANCE, "red")  # FCW declared as AEB: any impact red


def test_longitudinal_vrel_subtracts_target_speed():
    r = row(official_scenario="CBLA", vut=50.0, loc=0.5, vrel=None)
    r.update(collided=True, impact_speed_mps=25 * KPH, target_longitudinal_speed_mps=15 * KPH)
    cell = assess_2026([r]).cells[0]
    assert cell.kpi == pytest.approx(10.0) and cell.colour == "yellow"


def test_lsc_corner_cases_weigh_zero_as_the_calculator_does():
    rows = [
        row(official_scenario="CMCscp SfS", vut=None, loc=None, target_speed_kph=v, test_id=str(v))
        for v in (20, 30, 40, 50, 60, 70, 80)
    ]
    p = assess_2026(rows).scenarios["CMCscp SfS"]
    assert p.standard == pytest.approx(5 / 7 * 3.0)


def test_grid_lays_out_speed_by_impact_location():
    rows = [row(vut=v, loc=loc, vrel=(None if v < 40 else 5.0)) for v in (20, 40) for loc in (0.25, 0.75)]
    g = assess_2026(rows).grid("CPNA day")
    assert g.rows == ("20 km/h", "40 km/h") and g.columns == ("75%", "25%")
    assert g.colours == (("green", "green"), ("orange", "orange"))


@pytest.mark.parametrize(
    ("change", "field"),
    [({"range": "wide"}, "range"), ({"protocol": "2023"}, "protocol"),
     ({"official_scenario": "CCRs"}, "official_scenario"),
     ({"collided": True, "impact_speed_mps": None}, "impact_speed_mps")],
)  # fmt: skip
def test_bad_rows_name_the_field(change, field):
    with pytest.raises(UserInputError, match=field):
        assess_2026([row(**change)])


def test_duplicate_cells_and_unknown_claims_are_refused():
    with pytest.raises(UserInputError, match="same cell"):
        assess_2026([row(), dict(row(), test_id="other")])
    with pytest.raises(UserInputError, match="robustness_claims"):
        assess_2026([row()], {"CPNA": ["Sunshine"]})


def test_to_dict_is_json_ready():
    import json

    d = assess_2026([row(vrel=5.0)]).to_dict()
    assert json.loads(json.dumps(d))["scenarios"]["CPNA day"]["standard"] == pytest.approx(0.375)
    assert d["unverified"]


def test_taeb_from_a_hand_made_trace():
    time_s = np.arange(10) * 0.1
    accel = np.array([0, -0.5, -1.2, -2.5, -4.0, -5.0, -4.0, -2.0, -0.5, 0.0])
    assert taeb_s(time_s, accel) == pytest.approx(0.2)  # last < -3 at 0.6 s, back to the -1 crossing at 0.2 s
    assert taeb_s(time_s, np.zeros(10)) is None
    assert math.isnan(float("nan"))


def test_tables_equal_the_official_calculator():
    dm = pytest.importorskip("euroncap_rating_2026.crash_avoidance.data_model")
    for name, totals in t.TOTAL_POINTS.items():
        theirs = dm.TOTAL_SCORES[name]
        assert totals["standard"] == theirs["Standard"]
        assert totals.get("extended", 0.0) == theirs.get("Extended", 0.0)
        assert totals.get("robustness", 0.0) == (theirs.get("Robustness") or 0.0)
    for name, n in t.STANDARD_VERIFICATION_TESTS.items():
        assert dm.STANDARD_RANGE_VERIFICATION_TEST_NUM[name] == n
    assert t.VERIFICATION_SCALE_PCT["standard"] == dm.SCORE_FROM_VERIFICATION_TEST_OUTCOME["Standard"]
    assert t.VERIFICATION_SCALE_PCT["extended"] == dm.SCORE_FROM_VERIFICATION_TEST_OUTCOME["Extended"]
    for ours, key in (
        ("FC Pedestrian & Cyclist", ("FC", "Ped & Cyc")),
        ("LSC Pedestrian & Cyclist", ("LSC", "Ped & Cyc")),
    ):
        assert list(t.SUB_ELEMENTS[ours]) == dm.STAGE_SUBELEMENT_TO_LOADCASES[key[0]][key[1]]
    assert sum(t.TOTAL_POINTS[s]["standard"] for s in t.SUB_ELEMENTS["LSC Pedestrian & Cyclist"]) == 10.0
    fc = sum(sum(t.TOTAL_POINTS[s].values()) for s in t.SUB_ELEMENTS["FC Pedestrian & Cyclist"])
    assert fc == pytest.approx(20.0)


def test_cmrs_fcw_rows_are_judged_by_warning_or_bands_and_labelled_by_speed_only():
    from vrusim.ncap.rating2026.colours import colour_of, criterion_of, kpi_of

    row = {"official_scenario": "CMRs", "function": "FCW", "vut_speed_kph": 70.0, "collided": True,
           "impact_speed_mps": 25.0 / 3.6, "target_longitudinal_speed_mps": 0.0, "planner_warns": False}  # fmt: skip
    criterion = criterion_of(row)
    assert colour_of(row, criterion, kpi_of(row, criterion)) == "brown"  # 25 km/h at 70: the (20, 30] band
    warned = {**row, "planner_warns": True, "warning_ttc_s": 1.8}
    criterion = criterion_of(warned)
    assert colour_of(warned, criterion, kpi_of(warned, criterion)) == "green"
    assert colour_of({**warned, "warning_ttc_s": 1.6}, criterion, 1.6) == "red"


def test_cbda_is_yellow_when_the_door_is_held_and_red_on_contact():
    from vrusim.ncap.rating2026.colours import colour_of, criterion_of

    row = {"official_scenario": "CBDA", "function": "avoidance", "vut_speed_kph": 0.0, "collided": False}
    assert colour_of(row, criterion_of(row), 0.0) == "yellow"
    hit = {**row, "collided": True, "impact_speed_mps": 0.0}
    assert colour_of(hit, criterion_of(hit), 0.0) == "red"
