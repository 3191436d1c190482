"""LSC26 low-speed tests built by `ncap.build_low_speed`: every cell synchronised (first contact with the `none`
planner at the nominal impact location), dooring and pedal misapplication against their reference functions."""

from __future__ import annotations

import pytest

import vrusim.ncap.grid as grid
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
from vrusim.ncap.editions import edition

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
    assert cpmfc_distance_m("d1-IL50") == pytest.approx(1.125)
    assert cpmfc_distance_m("d2-IL50") == pytest.approx(2.625)


def test_turning_standstill_start_is_refused_with_a_reason():
    spec = edition("2026").scenario("CMFtap-SfS")
    test = NcapTest(spec, spec.cells[0], "day", "2026")
    with pytest.raises(ValueError, match="CMFtap SfS"):
        build_low_speed(test, "none", False)
