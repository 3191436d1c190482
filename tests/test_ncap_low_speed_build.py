"""LSC26 low-speed tests built by `ncap.build_low_speed`: every cell synchronised (first contact with the `none`
planner at the nominal impact location), dooring and pedal misapplication against their reference functions."""

from __future__ import annotations

import contextlib
import math

import numpy as np
import pytest

import vrusim.ncap.grid as grid
from vrusim.engine.simulate import simulate
from vrusim.geometry.paths import path_poses
from vrusim.metrics.summary import summary_rows
from vrusim.ncap.build import VUT, NcapTest, build_test
from vrusim.ncap.build_low_speed import (
    GO_ACCEL_MPS2,
    GO_SPEED_MPS,
    LOW_SPEED_LAYOUTS,
    build_low_speed,
    cpmfc_distance_m,
    start_off_probe_s,
    start_off_time_s,
)
from vrusim.ncap.build_turn_start import stop_station_m
from vrusim.ncap.editions import edition
from vrusim.ncap.first_contact import reference_point_at_first_contact
from vrusim.ncap.turn_placement import placed_turn_spec
from vrusim.scenario.routes import ego_route_spec

CODES = ("CBNAO-SfS", "CMCscp-SfS", "CPMRCm", "CPMFC", "CBDA")
TOLERANCE_M = 0.05
"""Synchronisation: the target's reference point within 5 cm of the nominal impact location at first contact."""


def test_build_test_hands_low_speed_layouts_to_the_low_speed_builder():
    for code in CODES:
        test = next(t for t in grid.select([code], protocol="2026") if t.spec.code == code)
        assert test.spec.layout in LOW_SPEED_LAYOUTS
        assert build_test(test, "none").scenario == build_low_speed(test, "none", False).scenario


def _run(code: str, planner: str) -> list[tuple]:
    tests = [t for t in grid.select([code], protocol="2026") if t.spec.code == code]
    assert tests, code
    run = grid.run_tests(tests, planner=planner)
    return list(zip(run.built, run.rows, summary_rows(run.run), strict=True))


@pytest.mark.parametrize("code", ["CBNAO-SfS", "CMCscp-SfS", "CPMRCm", "CPMFC"])
def test_every_cell_hits_at_the_nominal_location_without_a_function(code):
    for built, row, summary in _run(code, "none"):
        test = built.test
        assert row["collided"], test.test_id
        side = test.spec.impact_side
        expected_side = "rear" if "reverse" in test.spec.tags else side
        assert summary["impact_body_side"] == expected_side, test.test_id
        span_m = VUT["length_m"] if side in ("left", "right") else VUT["width_m"]
        error_m = (summary["impact_location"] - test.impact_location) * span_m
        assert abs(error_m) <= TOLERANCE_M, (test.test_id, error_m)
        assert summary["contact_time_s"] == pytest.approx(built.nominal.time_s, abs=0.02), test.test_id


def test_cbda_cyclist_hits_the_opened_door_without_a_function_and_not_with_dow():
    for built, row, summary in _run("CBDA", "none"):
        assert row["collided"] and summary["door_collision"], built.test.test_id
        assert summary["impact_body_side"] == "left"
    for built, row, summary in _run("CBDA", "dow"):
        assert not row["collided"], built.test.test_id
        assert summary["first_warning_s"] is not None


def test_cpmfc_acpe_avoids_the_child_and_suppresses_at_or_after_t_acc():
    for built, row, summary in _run("CPMFC", "acpe"):
        assert not row["collided"], built.test.test_id
        assert summary["first_mode_s"]["suppress"] is not None


def test_start_off_closed_form_by_hand():
    """1.5 m/s^2 to 10 km/h: ramp 2.7778^2 / 3 = 2.5720 m. 1.25 m: sqrt(2 * 1.25 / 1.5) = 1.2910 s;
    4.0 m: 2.7778 / 1.5 + (4.0 - 2.5720) / 2.7778 = 1.8519 + 0.5141 = 2.3660 s."""
    assert GO_ACCEL_MPS2 == 1.5 and pytest.approx(2.7778, abs=1e-4) == GO_SPEED_MPS
    assert start_off_time_s(1.25) == pytest.approx(1.2910, abs=1e-4)
    assert start_off_time_s(4.0) == pytest.approx(2.3660, abs=1e-4)


def test_cbnao_sfs_start_off_timing_by_hand():
    """d 1.50 m, EBT radius 0.25 m: the VUT front travels 1.25 m; the engine's start-off lags the closed form
    1.2910 s by the actuator (0.1 s lag, 30 m/s^3): 0.05-0.15 s. T0 on the step grid; the cyclist (10 km/h)
    starts v * (T0 + t_go) before the crossing point, and t_contact = T0 + t_go >= 4.5 s."""
    test = next(t for t in grid.select(["CBNAO-SfS"], protocol="2026") if t.cell.variant == "d1.50-T10")
    built = build_low_speed(test, "none", False)
    ego = built.scenario.ego
    t0 = ego.driver.phases[0].at_time_s
    lag_s = built.nominal.time_s - t0 - 1.2910
    assert 0.05 <= lag_s <= 0.15
    assert round(t0 / 0.01) == pytest.approx(t0 / 0.01, abs=1e-9) and built.nominal.time_s >= 4.5
    assert ego.start.x_m + VUT["length_m"] / 2 == pytest.approx(-1.5)
    cyclist = built.scenario.vrus[0]
    assert cyclist.start.x_m == 0.0
    assert cyclist.start.y_m == pytest.approx(-1.75 - 10 / 3.6 * built.nominal.time_s, abs=1e-9)
    probe = start_off_probe_s(ego.model_dump(), 1.25)
    assert built.nominal.time_s == pytest.approx(t0 + probe, abs=1e-9)


def test_cpmfc_distances_by_hand():
    """Creep 1.5 m/s at 1.0 m/s^2: d1 = 1.5^2 / 2 = 1.125 m; d2 = d1 + 1.5 m/s * 1 s = 2.625 m (UNVERIFIED)."""
    assert cpmfc_distance_m("d1") == pytest.approx(1.125)
    assert cpmfc_distance_m("d2") == pytest.approx(2.625)
    with pytest.raises(ValueError, match="expected d1 or d2"):
        cpmfc_distance_m("d3")


def test_turning_standstill_start_is_left_to_build_test():
    spec = edition("2026").scenario("CMFtap-SfS")
    test = NcapTest(spec, spec.cells[0], "day", "2026")
    with pytest.raises(ValueError, match=r"CMFtap SfS.*ncap\.build\.build_test"):
        build_low_speed(test, "none", False)


def _cmftap_sfs(planner: str = "none") -> list:
    return [build_test(t, planner) for t in grid.select(["CMFtap-SfS"], protocol="2026")]


def test_cmftap_sfs_stands_with_its_front_farside_corner_at_the_central_marking():
    """LSC26 §3.1.4: the front farside (left) corner on the inner side of the central marking, y = -0.10 / 2 m
    (the marking's centre line is y = 0 between the 3.5 m lanes), within the protocol's 0.10 m; the VUT faces
    along the 10 km/h farside path there, so between 0 and 2 alpha + beta = 90° to the left."""
    for built in _cmftap_sfs():
        ego = built.scenario.ego
        heading = math.radians(ego.start.heading_deg)
        corner_y = ego.start.y_m + VUT["length_m"] / 2 * math.sin(heading) + VUT["width_m"] / 2 * math.cos(heading)
        assert corner_y == pytest.approx(-0.05, abs=0.005)
        assert 0.0 < ego.start.heading_deg < 90.0
        assert ego.initial_speed_mps == 0.0 and ego.route.start_in_turn_m > 0.0
        assert ego.driver.phases[0].target_speed_mps == pytest.approx(GO_SPEED_MPS)


def test_cmftap_sfs_route_after_the_stop_is_the_protocol_path():
    """The route the VUT takes from its stop is the 10 km/h farside path of a moving CMFtap from the same
    station on (the exact poses, within 1 mm)."""
    built = _cmftap_sfs()[0]
    stop = stop_station_m("farside")
    stations = np.arange(0.0, 15.0, 0.5)
    got = path_poses(ego_route_spec(built.scenario.ego), stations)
    whole = path_poses(placed_turn_spec("farside", 10.0), stations + stop)
    for a, b in zip(got[:3], whole[:3], strict=True):
        np.testing.assert_allclose(a, b, atol=1e-3)


def test_cmftap_sfs_first_contact_at_the_nominal_location_without_a_function():
    """Planner `none`: the EMT (oncoming in the lane 1.75 m left of the centre marking) first touches the VUT
    front with its reference point at 50 % of the width (±5 cm), at the nominal time (±0.02 s)."""
    built = _cmftap_sfs()
    run = simulate([b.scenario for b in built], trace=True)
    offsets = reference_point_at_first_contact(built, run)
    for b, offset, summary in zip(built, offsets, summary_rows(run), strict=True):
        assert summary["collided"] and summary["impact_body_side"] == "front", b.test.test_id
        assert offset[1] == pytest.approx(0.0, abs=TOLERANCE_M), b.test.test_id
        assert offset[0] == pytest.approx(b.nominal.local_x_m, abs=TOLERANCE_M), b.test.test_id
        assert summary["contact_time_s"] == pytest.approx(b.nominal.time_s, abs=0.02), b.test.test_id
        assert b.scenario.vrus[0].start.y_m == pytest.approx(1.75) and b.scenario.vrus[0].heading_deg == 180.0


def test_cbda_cyclist_first_touches_the_opening_door_at_its_rear_edge_by_hand():
    """CBDA, EBT 15 km/h, gap 1.0 m. By hand, in the world frame (VUT centre (0, -1.75), heading +x): the hinge of
    the driver's door is 1.3 m behind the front and on the left side, H = (0.95, -0.85); the door (1.1 m long,
    0.1 m thick) opens rearward-outward at 60°/s from t = 3.0 s, when the cyclist's front is the 8.0 m door
    operation distance (LSC26 §3.2.3) behind the door's rearmost point x = -0.15; at angle θ it spans H + u·d
    + w·n, u in [0, 1.1], w in [0, 0.1], with d = (-cos θ, sin θ), n = (sin θ, cos θ). The cyclist's circle
    (r = 0.25 m) rides y = -1.75 + 0.9 + 1.0 = 0.15 m at 15 km/h. Scanning t at 1 ms: the first t at which
    the circle's centre is within r of the door rectangle is the first contact, on the door's rear edge."""
    test = next(
        t for t in grid.select(["CBDA"], protocol="2026") if t.cell.gap_m == 1.0 and t.cell.target_speed_kph == 15.0
    )
    built = build_test(test, "none")
    run = grid.run_tests([test], planner="none")
    vru = built.scenario.vrus[0]
    v, r = 15.0 / 3.6, 0.25
    assert vru.start.y_m == pytest.approx(0.15) and vru.radius_m == pytest.approx(r)
    assert vru.start.x_m + r + v * 3.0 == pytest.approx(-0.15 - 8.0)  # front 8.0 m from the door at t = 3.0 s
    hinge = (0.95, -0.85)
    t_s = 3.0 + np.arange(0.0, 3.0, 0.001)
    theta = np.radians(np.minimum(60.0 * (t_s - 3.0), 60.0))
    d = np.stack([-np.cos(theta), np.sin(theta)], axis=1)
    n = np.stack([np.sin(theta), np.cos(theta)], axis=1)
    rel = np.stack([vru.start.x_m + v * t_s - hinge[0], np.full_like(t_s, vru.start.y_m - hinge[1])], axis=1)
    along, across = (rel * d).sum(axis=1), (rel * n).sum(axis=1)
    gap_u = np.maximum(np.maximum(-along, along - 1.1), 0.0)
    gap_w = np.maximum(np.maximum(-across, across - 0.1), 0.0)
    first = int(np.argmax(np.hypot(gap_u, gap_w) <= r))
    assert first > 0
    assert run.rows[0]["collided"] and run.run.metrics.contact_time_s[0] == pytest.approx(t_s[first], abs=0.011)
    nearest_u = min(max(along[first], 0.0), 1.1)  # the door point nearest the circle's centre, along the door
    assert nearest_u == pytest.approx(1.1, abs=0.05)  # the circle meets the door's rear edge


def test_batched_probes_build_the_same_tests_with_one_probe_batch(monkeypatch):
    """`ncap.probes.batched_probes` runs every start-off / pedal probe of the low-speed tests in one batch; the
    tests built from it equal those built with one probe run each (a run is bit-identical alone and in a batch)."""
    import functools

    from vrusim.ncap import probes
    from vrusim.ncap.build import build_test
    from vrusim.ncap.build_low_speed import LOW_SPEED_LAYOUTS
    from vrusim.ncap.grid import select

    tests = [t for t in select(night=True, protocol="2026") if t.spec.layout in LOW_SPEED_LAYOUTS]
    monkeypatch.setattr(probes, "_RUNS", {})
    single = [build_test(t).scenario.model_dump_json() for t in tests]
    batches = []
    run = probes._run
    monkeypatch.setattr(probes, "_run", lambda keys: (batches.append(len(keys)), run(keys))[1])
    monkeypatch.setattr(probes, "_RUNS", {})
    probes.batched_probes([functools.partial(build_test, t) for t in tests])
    assert len(batches) == 1 and batches[0] >= 3  # start-off forward / reversing, pedal misapplication
    assert [build_test(t).scenario.model_dump_json() for t in tests] == single
    assert len(batches) == 1  # the second build ran no probe


def test_probe_stations_are_those_of_a_traced_run(monkeypatch):
    """A probe batch steps the engine without a trace (`ncap.probes._stations`); its times and route stations are
    the `t_s` and `ego_station_m` of `simulate(..., trace=True)`, bit for bit, every row of every probe."""
    from vrusim.ncap import probes
    from vrusim.ncap.build_low_speed import LOW_SPEED_LAYOUTS
    from vrusim.ncap.grid import select

    tests = [t for t in select(night=True, protocol="2026") if t.spec.layout in LOW_SPEED_LAYOUTS]
    monkeypatch.setattr(probes, "_RUNS", {})
    with probes._collect() as needed:  # the probes the low-speed tests ask for (not run while collecting)
        for test in tests:
            with contextlib.suppress(probes.ProbeNeeded):
                build_test(test)
    scenarios = [probes._scenario(key) for key in sorted(needed)]
    assert len(scenarios) >= 3 and len({key[1] for key in needed}) >= 2  # several probes, several durations
    trace = simulate(scenarios, trace=True).trace
    t_s, station_m = probes._stations(scenarios)
    np.testing.assert_array_equal(t_s, trace["t_s"], strict=True)
    np.testing.assert_array_equal(station_m, trace["ego_station_m"], strict=True)
    assert station_m[-1].min() > 0.0  # the egos moved
