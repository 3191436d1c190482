"""Euro NCAP catalogue: with no reaction (planner `none`) every test of every family meets its nominal impact.

The nominal impact instant is the first contact of the bodies (FC26; tests/test_ncap_sync.py): at it the
target's reference point must sit at its designed place on the VUT (across: the protocol's impact location)
within ±0.05 m both across and along the VUT, with the target at its steady speed.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from vrusim.engine.simulate import simulate
from vrusim.geometry.paths import SAMPLE_SPACING_M, sample_path
from vrusim.ncap.assess import assess
from vrusim.ncap.build import build_test
from vrusim.ncap.editions.v2023 import SCENARIOS
from vrusim.ncap.grid import run_tests, select
from vrusim.scenario.routes import ego_route_spec

TOLERANCE_M = 0.05
CONTACT_LEAD_S = 0.011
"""The nominal instant is the first contact (synchronisation at first contact, tests/test_ncap_sync.py); the
engine reports it within one step."""


def _families() -> list[str]:
    return [s.code for s in SCENARIOS]


def _no_stop(scenario):
    data = scenario.model_dump()
    data["sim"]["stop_on_collision"] = False
    return type(scenario).model_validate(data)


def _interp(t, series, at):
    return float(np.interp(at, t, series))


@pytest.mark.parametrize("code", _families())
def test_every_test_meets_its_nominal_impact_location(code):
    built = [build_test(test, planner="none") for test in select(protocol="2023", codes=[code])]
    run = simulate([_no_stop(b.scenario) for b in built], trace=True)
    trace = run.trace
    t = trace["t_s"]
    for b_index, b in enumerate(built):
        nominal = b.nominal
        at = nominal.time_s
        hx = _interp(t, trace["ego_heading_x"][:, b_index], at)
        hy = _interp(t, trace["ego_heading_y"][:, b_index], at)
        norm = math.hypot(hx, hy)
        hx, hy = hx / norm, hy / norm
        cx = _interp(t, trace["ego_x_m"][:, b_index], at)
        cy = _interp(t, trace["ego_y_m"][:, b_index], at)
        vx = _interp(t, trace["vru_x_m"][:, b_index, 0], at)
        vy = _interp(t, trace["vru_y_m"][:, b_index, 0], at)
        # the reference point lies behind the footprint centre along the target's heading
        rx = vx - nominal.ref_behind_centre_m * math.cos(nominal.target_heading_rad)
        ry = vy - nominal.ref_behind_centre_m * math.sin(nominal.target_heading_rad)
        local_x = (rx - cx) * hx + (ry - cy) * hy
        local_y = -(rx - cx) * hy + (ry - cy) * hx
        test_id = b.test.test_id
        assert local_x == pytest.approx(nominal.local_x_m, abs=TOLERANCE_M), f"{test_id}: along {local_x:.3f}"
        assert local_y == pytest.approx(nominal.local_y_m, abs=TOLERANCE_M), f"{test_id}: across {local_y:.3f}"
        if b.test.spec.headway_s == 0:  # a braking target is, by design, not steady at the impact
            speed = _interp(t, trace["vru_speed_mps"][:, b_index, 0], at)
            assert speed == pytest.approx(b.test.target_speed_mps, abs=1e-6), f"{test_id}: not steady"
        # the bodies first touch at the nominal instant
        contact = run.metrics.contact_time_s[b_index]
        assert run.metrics.collided[b_index], f"{test_id}: no contact"
        assert at - CONTACT_LEAD_S <= contact <= at + 0.01, f"{test_id}: contact at {contact:.3f}, nominal {at:.3f}"


def test_catalogue_lists_every_family_of_the_issue():
    codes = set(_families())
    required = {
        "CPFA-50", "CPNA-25", "CPNA-75", "CPNCO-50", "CPLA-50", "CPLA-25", "CPTAfs", "CPTAfo", "CPTAns", "CPTAno",
        "CPRA-Cm", "CPRA-Cs", "CBNA-50", "CBNAO-50", "CBFA-50", "CBLA-50", "CBLA-25", "CBTAfs", "CBTAfo",
        "CBTAns", "CBTAno", "CMRs", "CMRb", "CMFtap", "CENA-50", "CEFA-50", "CELA-50", "CETAfs",
    }  # fmt: skip
    assert required <= codes


def test_grid_sizes_follow_the_protocol():
    assert len(select(protocol="2023", codes=["CPNA-25"])) == 11  # 10..60 km/h in 5 km/h steps, day
    assert len(select(protocol="2023", codes=["CPNA-25"], night=True)) == 22
    assert len(select(protocol="2023", codes=["CPLA-50"])) == 9  # 20..60
    assert len(select(protocol="2023", codes=["CMFtap"])) == 9  # 3 VUT x 3 EMT speeds
    assert len(select(protocol="2023", codes=["CPRA-Cs"])) == 6


def test_fsm_runs_the_whole_grid_into_a_complete_scorecard():
    tests = select(night=True, protocol="2023")
    result = run_tests(tests, planner="fsm", v2x=False)
    assert len(result.rows) == len(tests) > 240
    for row in result.rows:
        assert row["collided"] == (row["impact_speed_mps"] is not None)
        for value in row.values():
            assert not (isinstance(value, float) and math.isnan(value))
    assessment = assess(result.rows)
    for group in assessment.groups:
        assert group.not_assessed == (), (group.group, group.not_assessed)
    assert 0.0 < assessment.total <= 23.0


@pytest.mark.parametrize("speed_kph", [10.0, 30.0, 40.0])
def test_cpnco_child_hidden_by_the_parked_cars_until_it_steps_into_view(speed_kph):
    """Catalogue CPNCO: never perceived while the parked cars hide it; perceived within 0.1 s of the first
    step at which an independent 601-ray line-of-sight check sees part of its footprint inside the sector."""
    from test_occlusion import brute_force_clear, in_sector, states

    test = next(t for t in select(protocol="2023", codes=["CPNCO-50"]) if t.cell.vut_speed_kph == speed_kph)
    scenario = build_test(test, planner="none").scenario
    trace = simulate([scenario], trace=True).trace
    apex_x, apex_y, heading, vx, vy = states(scenario, trace)
    detected = trace["vru_detected"][:, 0, 0]
    radius = scenario.vrus[0].footprint_m
    visible = np.zeros(len(detected), dtype=bool)
    for i in range(len(detected)):
        apex = (apex_x[i], apex_y[i])
        clear, ends = brute_force_clear(apex, (vx[i], vy[i]), radius, scenario.obstacles, 601)
        visible[i] = bool(np.any(clear & in_sector(apex, heading[i], ends, scenario.sensor.range_m, 120.0)))
    assert not np.any(detected & ~visible), "perceived while hidden"
    first_visible, first_detected = int(np.argmax(visible)), int(np.argmax(detected))
    assert visible.any() and detected.any()
    assert 0 <= (first_detected - first_visible) * scenario.sim.dt_s <= 0.1 + 1e-9
    # the obstruction matters here: without it the child would be perceived earlier (from about 50 km/h on,
    # the 20 m sensor range, not the cars, limits the first perception)
    data = scenario.model_dump()
    data["obstacles"] = []
    open_view = simulate([type(scenario).model_validate(data)])
    assert open_view.metrics.first_sensor_s[0] < first_detected * scenario.sim.dt_s


def test_fcw_rows_are_judged_by_the_warning_of_a_planner_that_warns():
    """A plug-in planner that warns on first detection and never brakes: FCW rows get green or red by the
    TTC of that warning (>= 1.7 s), AEB rows collide and are judged by impact speed."""
    tests = select(protocol="2023", codes=["CPLA-25", "CBLA-25"])
    result = run_tests(tests, planner="warning_planner:WarnOnDetection")
    assessment = assess(result.rows)
    for row, assessed in zip(result.rows, assessment.tests, strict=True):
        assert row["planner_warns"] is True
        assert row["warning_ttc_s"] is not None and row["collided"]
        assert assessed.criterion != "AEB fallback (planner issues no warnings)"
        assert assessed.colour == ("green" if row["warning_ttc_s"] >= 1.7 else "red")
    colours = {a.colour for a in assessment.tests}
    assert colours == {"green", "red"}  # the 20 m sensor warns early enough at 50 km/h but not at 80 km/h


def test_turns_end_on_the_centre_line_of_the_right_lane_of_the_road_turned_into():
    for test in select(protocol="2023", codes=["CPTA", "CBTA", "CMFtap", "CETAfs"]):
        ego = build_test(test, planner="none").scenario.ego
        samples = sample_path(ego_route_spec(ego))
        route = ego.route
        end = samples[math.ceil((route.turn_at_m + route.turn_length_m) / SAMPLE_SPACING_M)]
        expected_x = 1.75 if route.kind == "left" else -1.75
        assert end[0] == pytest.approx(expected_x, abs=0.01), test.test_id
        assert abs(end[2]) == pytest.approx(0.0, abs=2e-4), test.test_id  # heading ±90° within 0.01°


def test_obstruction_placement_matches_the_protocol_figures():
    """Hand-computed from V23/FC26: CPNCO cars 1.0 m clear of the VUT side, small car's front 1.0 m before
    the child's path edge, SUV 1.0 m behind; CBNA row ends 17 m from the VUT lane centre line, 1.0 m clear
    of the cyclist, SUV first, 0.2 m gap."""
    cpnco = build_test(select(protocol="2023", codes=["CPNCO-50"])[0], planner="none").scenario.obstacles
    small, suv = cpnco
    assert (small.kind, suv.kind) == ("small car", "SUV")
    child_half_width = 0.298 / 2
    assert small.centre.x_m + small.length_m / 2 == pytest.approx(-child_half_width - 1.0)
    assert suv.centre.x_m + suv.length_m / 2 == pytest.approx(small.centre.x_m - small.length_m / 2 - 1.0)
    for car in cpnco:
        assert car.centre.y_m + car.width_m / 2 == pytest.approx(-1.75 - 0.9 - 1.0)  # 1.0 m clear of the VUT
    cbna = build_test(select(protocol="2023", codes=["CBNA-50"])[0], planner="none").scenario
    suv, small = cbna.obstacles
    path_x = 1.75  # the cyclist rides in the right lane of the nearside arm
    assert (suv.kind, small.kind) == ("SUV", "small car")
    assert suv.centre.y_m + suv.length_m / 2 == pytest.approx(-1.75 - 17.0)
    assert small.centre.y_m + small.length_m / 2 == pytest.approx(suv.centre.y_m - suv.length_m / 2 - 0.2)
    for car in cbna.obstacles:
        assert car.centre.x_m + car.width_m / 2 == pytest.approx(path_x - 0.25 - 1.0)
    assert cbna.vrus[0].start.x_m == pytest.approx(path_x)


def test_a_test_gives_the_same_row_alone_and_inside_the_whole_grid():
    tests = select(night=True, protocol="2023")
    grid = {row["test_id"]: row for row in run_tests(tests, planner="fsm", v2x=True).rows}
    for test_id in ("CPNCO-50/30kph/night", "CMFtap/15kph/EMT45/day", "CPRA-Cs/8kph/IL75-adult/day"):
        test = next(t for t in tests if t.test_id == test_id)
        assert run_tests([test], planner="fsm", v2x=True).rows[0] == grid[test_id]
