"""Euro NCAP synchronisation at first contact (FC26 Definitions "Vimpact", §1.2.5).

Without a VUT reaction the VUT rectangle must first touch the target's contact circle with the target's
reference point at the nominal impact location: across the leading edge at the impact location (front and rear
impacts), along the side at the impact location of the length (side impacts). Measured from traced runs of the
whole 2023 catalogue and every 2026 test with a moving VUT (the low-speed layouts have tests of their own,
tests/test_ncap_low_speed_build.py), and checked against hand-computed first contacts.
"""

from __future__ import annotations

import functools
import math

import numpy as np
import pytest

from vrusim.engine.simulate import simulate
from vrusim.ncap.build import VUT, build_test
from vrusim.ncap.editions import edition
from vrusim.ncap.first_contact import reference_point_at_first_contact
from vrusim.ncap.grid import select
from vrusim.ncap.protocol import KPH

TOLERANCE_M = 0.05
LENGTH, WIDTH = VUT["length_m"], VUT["width_m"]


LOW_SPEED_LAYOUTS = ("standstill_start", "pedal_misapplication", "dooring")
"""Layouts of LSC26 tests whose VUT starts from rest or stands (checked in tests/test_ncap_low_speed_build.py)."""
FAMILIES = [
    (name, spec.code)
    for name in ("2023", "2026")
    for spec in edition(name).scenarios
    if spec.layout not in LOW_SPEED_LAYOUTS and any(cell.vut_speed_kph > 0 for cell in spec.cells)
]


@functools.cache
def _catalogue(protocol: str):
    """Every day test of the edition's FAMILIES, built for `none` and run as one traced batch."""
    tests = [t for t in select(protocol=protocol, night=False) if (protocol, t.spec.code) in FAMILIES]
    built = [build_test(test, planner="none") for test in tests]
    run = simulate([b.scenario for b in built], trace=True)
    return built, run, reference_point_at_first_contact(built, run)


def _protocol_location(test) -> tuple[str, float]:
    """("across" | "along", the protocol's nominal coordinate in the simulated frame from the rectangle centre)."""
    if test.spec.impact_side != "front":  # % of the length from the rear (FC26 §1.2.5)
        return "along", test.impact_location * LENGTH - LENGTH / 2
    across = (test.impact_location - 0.5) * WIDTH  # 0 % = the vehicle's right edge
    return "across", -across if test.spec.layout == "reverse" else across


@pytest.mark.parametrize("family", FAMILIES, ids=[f"{name}:{code}" for name, code in FAMILIES])
def test_every_cell_first_touches_with_the_reference_point_at_the_nominal_location(family):
    built, run, offsets = _catalogue(family[0])
    cells = [i for i, b in enumerate(built) if b.test.spec.code == family[1]]
    assert cells
    for i in cells:
        b = built[i]
        test_id = b.test.test_id
        assert run.metrics.collided[i], f"{test_id}: no contact"
        ahead, left = offsets[i]
        which, nominal = _protocol_location(b.test)
        if which == "across":
            assert left == pytest.approx(nominal, abs=TOLERANCE_M), f"{test_id}: across {left:.3f}"
            # along: at or just beyond the leading edge (by at most the circle's radius plus the reference
            # point's offset from the circle centre)
            assert ahead == pytest.approx(b.nominal.local_x_m, abs=TOLERANCE_M), f"{test_id}: along {ahead:.3f}"
            radius = b.scenario.vrus[0].radius_m
            reach = radius + abs(b.nominal.ref_behind_centre_m)
            assert LENGTH / 2 - reach - 1e-9 <= b.nominal.local_x_m <= LENGTH / 2 + reach + 1e-9
        else:
            assert ahead == pytest.approx(nominal, abs=TOLERANCE_M), f"{test_id}: along {ahead:.3f}"
            assert left == pytest.approx(b.nominal.local_y_m, abs=TOLERANCE_M), f"{test_id}: across {left:.3f}"
            # beside the side face, within the circle's reach (an oblique approach touches before the reference
            # point reaches the face)
            reach = b.scenario.vrus[0].radius_m + abs(b.nominal.ref_behind_centre_m)
            assert -1e-9 <= abs(b.nominal.local_y_m) - WIDTH / 2 <= reach
        # the nominal instant is the first contact
        assert run.metrics.contact_time_s[i] == pytest.approx(b.nominal.time_s, abs=0.011), test_id


def _one(code: str, speed_kph: float, variant: str = ""):
    test = next(
        t for t in select([code], protocol="2023") if t.cell.vut_speed_kph == speed_kph and t.cell.variant == variant
    )
    built = build_test(test, planner="none")
    run = simulate([built.scenario], trace=True)
    return built, run, reference_point_at_first_contact([built], run)[0]


def _at(run, name: str, t: float) -> float:
    series = run.trace[name][:, 0] if run.trace[name].ndim == 2 else run.trace[name][:, 0, 0]
    return float(np.interp(t, run.trace["t_s"], series))


def test_slow_car_meets_a_fast_farside_cyclist_with_the_crank_on_its_centre_line():
    """CBFA, VUT 10 km/h, EBTa 20 km/h from the farside (heading -y) on the path x = -1.75 m, IL 50 %.

    By hand: the circle (r = 0.25 m) is centred 0.015 m behind the crank (box 1.89 m, crank 0.96 m from its
    rear); with the crank on the VUT centre line y = -1.75 the circle first touches the front face when the
    face is at x = -1.75 - 0.25 = -2.0. The VUT front starts at start_x + 2.25, so contact comes after
    (-2.0 - front_0) / v. The old synchronisation (crank meeting the front line) let the cyclist ride on for
    0.25 m of VUT travel, 0.09 s = 0.5 m at 20 km/h, before its crank reached the centre line.
    """
    built, run, offset = _one("CBFA-50", 10.0)
    v = 10.0 * KPH
    front_0 = built.scenario.ego.start.x_m + LENGTH / 2
    expected_t = (-2.0 - front_0) / v
    assert run.metrics.contact_time_s[0] == pytest.approx(expected_t, abs=0.011)
    assert built.nominal.time_s == pytest.approx(expected_t, abs=1e-6)
    crank_y = _at(run, "vru_y_m", expected_t) - 0.015  # the centre is 0.015 m behind the crank (heading -y)
    assert crank_y == pytest.approx(-1.75, abs=0.01)
    assert _at(run, "vru_x_m", expected_t) == pytest.approx(-1.75, abs=1e-9)
    assert offset == pytest.approx([LENGTH / 2 + 0.25, 0.0], abs=0.01)


def test_turning_vut_first_touches_the_pedestrian_with_its_hip_on_the_centre_line():
    """CPTAfs 10 km/h: at the first contact read from the trace, by hand geometry in the VUT frame: the hip
    (0.06 m behind the circle centre along the walking direction +x, on the line y = 9.5 m) lies on the VUT
    centre line, and the circle (r = 0.25 m) touches the flat front face: its centre is r ahead of it."""
    built, run, offset = _one("CPTAfs", 10.0)
    t = built.nominal.time_s
    assert run.metrics.contact_time_s[0] == pytest.approx(t, abs=0.011)
    hx, hy = _at(run, "ego_heading_x", t), _at(run, "ego_heading_y", t)
    norm = math.hypot(hx, hy)
    hx, hy = hx / norm, hy / norm
    cx, cy = _at(run, "ego_x_m", t), _at(run, "ego_y_m", t)
    px, py = _at(run, "vru_x_m", t), _at(run, "vru_y_m", t)
    hip_x, hip_y = px - 0.06, py
    assert py == pytest.approx(9.5, abs=1e-9)
    hip_left = -(hip_x - cx) * hy + (hip_y - cy) * hx
    centre_ahead = (px - cx) * hx + (py - cy) * hy
    centre_left = -(px - cx) * hy + (py - cy) * hx
    assert hip_left == pytest.approx(0.0, abs=0.01)
    assert abs(centre_left) < WIDTH / 2  # on the flat face
    assert centre_ahead == pytest.approx(LENGTH / 2 + 0.25, abs=0.01)
    assert offset[1] == pytest.approx(0.0, abs=0.01)


def test_reversing_vut_first_touches_the_crossing_child_at_half_its_rear_width():
    """CPRA-Cm, child: VUT reversing at 8 km/h along y = -1.75 towards the child's path x = 0; its rear axle
    starts 10 m from the collision point, so the rear bumper starts 10 - 0.9 = 9.1 m away. The EPTc circle
    (r = 0.149 m) is centred 0.0405 m ahead of the hip (box 0.711 m, hip 0.315 m from its rear) along +y; with
    the hip at (0, -1.75) the circle first touches the bumper at x = 0.149: after (9.1 - 0.149) / v = 4.0280 s.
    The child starts 4.0 m before that point, accelerates over 1.5 m to 5 km/h: 3.96 s to get there."""
    built, run, offset = _one("CPRA-Cm", 8.0, "child")
    v = 8.0 * KPH
    assert built.scenario.ego.start.x_m - LENGTH / 2 == pytest.approx(9.1)  # the rear bumper
    expected_t = (9.1 - 0.149) / v
    assert expected_t == pytest.approx(4.0280, abs=1e-4)
    assert built.nominal.time_s == pytest.approx(expected_t, abs=1e-6)
    assert run.metrics.contact_time_s[0] == pytest.approx(expected_t, abs=0.011)
    walk_s = 2 * 1.5 / (5 * KPH) + 2.5 / (5 * KPH)
    assert built.scenario.vrus[0].trigger.ego_route_m == pytest.approx(v * (expected_t - walk_s), abs=1e-6)
    hip_y = _at(run, "vru_y_m", expected_t) - 0.0405
    assert hip_y == pytest.approx(-1.75, abs=0.01)
    assert offset == pytest.approx([LENGTH / 2 + 0.149, 0.0], abs=0.01)


def test_motorcycle_front_wheel_first_touches_the_vut_side_at_90_percent_of_its_length():
    """2026 CMCscp, VUT 30 km/h along +x on y = -1.75, EMT 50 km/h from the nearside (heading +y). By hand: the
    EMT circle (r = 0.395 m, half its 0.79 m width) sits r behind the front of the front wheel (the crossing
    reference, FC26 §1.4.1.3); it first touches the right face y = -1.75 - 0.9 = -2.65 with its top point when
    the wheel front is on the face. 90 % of the 4.5 m length from the rear is 4.05 - 2.25 = 1.8 m ahead of the
    VUT's centre, so at contact the VUT centre is at x_path - 1.8 and the wheel front at (x_path, -2.65):
    contact after (x_path - 1.8 - x_0) / v_vut, and the EMT has come from its start at 50 km/h."""
    test = next(
        t
        for t in select(["CMCscp"], protocol="2026")
        if t.spec.code == "CMCscp" and t.cell.vut_speed_kph == 30.0 and t.cell.target_speed_kph == 50.0
    )
    built = build_test(test, planner="none")
    run = simulate([built.scenario], trace=True)
    vru = built.scenario.vrus[0]
    x_path = vru.start.x_m
    v, v_emt = 30.0 * KPH, 50.0 * KPH
    expected_t = (x_path - 1.8 - built.scenario.ego.start.x_m) / v
    wheel_front_y0 = vru.start.y_m + 0.395
    assert wheel_front_y0 + v_emt * expected_t == pytest.approx(-2.65, abs=1e-6)
    assert run.metrics.contact_time_s[0] == pytest.approx(expected_t, abs=0.011)
    offset = reference_point_at_first_contact([built], run)[0]
    assert offset == pytest.approx([1.8, -0.9], abs=0.01)


def test_the_closed_form_on_straight_roads_agrees_with_the_general_solver():
    """Every straight-road 2023 front impact: the closed form (`straight_gap_m`) against `front_first_contact`
    run on a sampled straight route."""
    from vrusim.ncap.build import _footprint, _geometry, _target_line, _target_travel, _vut_point
    from vrusim.ncap.first_contact import front_first_contact

    for test in select(protocol="2023"):
        spec = test.spec
        if spec.layout in ("turning", "oncoming") or spec.impact_side != "front":
            continue
        along, left = _vut_point(test)
        point, direction = _target_line(test)
        if _target_travel(test) == "still" and spec.layout == "reverse":
            direction = np.array([0.0, -1.0])
        radius, centre_ahead = _footprint(test)
        geometry = _geometry(test, along, left, radius, centre_ahead)
        travel = -1.0 if spec.layout == "reverse" else 1.0
        s = np.arange(0.0, 20.0 + 1e-9, 0.2)
        x0 = point[0] - travel * 15.0 - travel * along
        samples = np.column_stack([x0 + travel * s, np.full_like(s, -1.75), np.full_like(s, travel), 0 * s, 0 * s])
        across = np.array([0.0, 1.0])  # targets ahead: their collision point's line across the VUT path
        line = across if spec.layout in ("longitudinal", "rear") else direction
        station, ref, ahead = front_first_contact(samples, geometry, point, line, heading=direction)
        built = build_test(test, planner="none")
        assert ahead == pytest.approx(built.nominal.local_x_m - along + geometry["rear_to_centre_m"], abs=1e-3)
        assert station == pytest.approx(15.0 - ahead, abs=1e-3)
        if spec.headway_s == 0:  # a braking lead meets the VUT elsewhere (its own timing)
            assert ref == pytest.approx([built.nominal.impact_x_m, built.nominal.impact_y_m], abs=1e-9)


def test_cbfa_parked_pair_ends_at_the_steady_state_point():
    """CBFA (V23 / FC26 Fig. 3-27): SUV nearest the junction, its junction-side end 22 m from the collision point
    (VUT lane centre line y = -1.75 m) along the farside arm, 1.0 m clear of the cyclist (path x = -1.75 m,
    half width 0.25 m) on the VUT's side; the small car 0.2 m beyond it."""
    scenario = build_test(select(["CBFA-50"], protocol="2023")[0], planner="none").scenario
    suv, small = scenario.obstacles
    assert (suv.kind, small.kind) == ("SUV", "small car")
    assert suv.centre.y_m - suv.length_m / 2 == pytest.approx(-1.75 + 22.0)
    assert small.centre.y_m - small.length_m / 2 == pytest.approx(suv.centre.y_m + suv.length_m / 2 + 0.2)
    for car in (suv, small):
        assert car.centre.x_m + car.width_m / 2 == pytest.approx(-1.75 - 0.25 - 1.0)
