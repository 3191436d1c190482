"""Issue 17's metrics, each against a value computed by hand from its formula on a simple geometry.

Ego (conftest: 4.5 m x 1.8 m, l = 2.25, w = 0.9) drives straight along +x at 10 m/s with the `none` planner
(it holds its speed); VRUs are discs of radius 0.5 m. Definitions: docs/metrics.md.
"""

from __future__ import annotations

import copy
import json
import math

import numpy as np
import pyarrow as pa
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from conftest import minimal_scenario_dict
from vrusim.cli.app import app
from vrusim.engine.simulate import simulate
from vrusim.errors import UserInputError
from vrusim.metrics.columns import result_columns
from vrusim.metrics.injury_risk import CURVES, FATALITY_CURVES, MPH_PER_MPS, risk
from vrusim.metrics.summary import summary_rows
from vrusim.metrics.surrogates import plastic_delta_v
from vrusim.scenario.loading import scenario_from_mapping
from vrusim.scenario.schema import MetricsSettings
from vrusim.sweep.tables import chunk_table

DT = 0.01
L, W, R, V = 2.25, 0.9, 0.5, 10.0


def vru(x: float, y: float, speed: float = 0.0, heading: float = 90.0, **extra) -> dict:
    """A pedestrian disc (radius R) at (x, y) moving at a constant `speed` along `heading_deg` from t = 0."""
    return {
        "type": "pedestrian", "start": [x, y], "heading_deg": heading, "radius_m": R,
        "top_speed_mps": speed, "initial_speed_mps": speed, **extra,
    }  # fmt: skip


def row(vrus: list[dict], duration: float = 6.0, ego_x: float = 0.0, **changes) -> dict:
    data = minimal_scenario_dict()
    data["vrus"] = vrus
    data["ego"]["start"]["x_m"] = ego_x
    data["sim"]["duration_s"] = duration
    for key, value in changes.items():
        data[key] = {**data.get(key, {}), **value}
    return summary_rows(simulate([scenario_from_mapping(data, "case.yaml")]))[0]


# ----------------------------------------------------------------------------------------------- collision severity


@pytest.fixture(scope="module")
def head_on() -> dict:
    """A standing pedestrian on the ego's centre line at x = 30: contact when the front reaches 29.5 m."""
    return row([vru(30.0, 0.0, mass_kg=100.0)], ego={"mass_kg": 1000.0, "start": {"x_m": 0.0, "y_m": 0.0}})


def test_delta_v_and_speed_reduction_of_a_head_on_contact(head_on):
    assert head_on["collided"] and head_on["contact_time_s"] == pytest.approx((29.5 - L) / V, abs=1e-6)
    assert head_on["speed_reduction_mps"] == pytest.approx(0.0, abs=1e-9)  # `none` never brakes: 10 - 10
    # plastic collision, m_e = 1000 kg, m_v = 100 kg, |v_rel| = 10 m/s
    assert head_on["delta_v_ego_mps"] == pytest.approx(100 / 1100 * 10, abs=1e-6)
    assert head_on["delta_v_vru_mps"] == pytest.approx(1000 / 1100 * 10, abs=1e-6)


def test_injury_risk_at_the_impact_speed(head_on):
    # Rosén & Sander (2009): 36 km/h -> 1 / (1 + exp(6.9 - 0.090 * 36))
    assert head_on["fatality_risk"] == pytest.approx(1 / (1 + math.exp(6.9 - 0.090 * 36.0)), abs=1e-4)
    assert head_on["serious_injury_risk"] == pytest.approx(float(risk(10.0, "tefft_2013_ais4")), abs=1e-4)


def test_default_masses_and_an_avoided_run_score_no_severity():
    hit = row([vru(30.0, 0.0)])
    assert hit["delta_v_ego_mps"] == pytest.approx(75 / 1575 * 10, abs=1e-6)  # 1500 kg ego, 75 kg pedestrian
    clear = row([vru(30.0, 3.0)])
    assert not clear["collided"]
    assert clear["speed_reduction_mps"] is None
    assert clear["delta_v_ego_mps"] == clear["delta_v_vru_mps"] == clear["fatality_risk"] == 0.0


def test_risk_matches_the_published_curves_at_three_speeds():
    for kmh in (30.0, 50.0, 70.0):  # Rosén & Sander (2009): a = 6.9, b = 0.090 per km/h
        expected = 1.0 / (1.0 + math.exp(6.9 - 0.090 * kmh))
        assert risk(kmh / 3.6, "rosen_sander_2009") == pytest.approx(expected, rel=1e-12)
    assert risk(50 / 3.6, "rosen_sander_2009") == pytest.approx(0.0832, abs=1e-4)
    # Tefft (2013), abstract: death 10 % at 24.1 mph, 50 % at 40.6 mph, 90 % at 54.6 mph; AIS 4+ at 17.1 / 33.0 / 48.1
    for curve, points in (("tefft_2013", (24.1, 40.6, 54.6)), ("tefft_2013_ais4", (17.1, 33.0, 48.1))):
        for mph, expected in zip(points, (0.10, 0.50, 0.90), strict=True):
            assert risk(mph / MPH_PER_MPS, curve) == pytest.approx(expected, abs=1e-12), (curve, mph)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.floats(-5.0, 80.0), min_size=2, max_size=20), st.sampled_from(sorted(CURVES)))
def test_risk_is_a_probability_increasing_with_speed(speeds, curve):
    values = risk(np.sort(speeds), curve)
    assert np.all((values >= 0.0) & (values <= 1.0))
    assert np.all(np.diff(values) >= -1e-15)


@settings(max_examples=60, deadline=None)
@given(st.floats(100.0, 60_000.0), st.floats(1.0, 1000.0), st.floats(0.0, 60.0))
def test_delta_v_conserves_momentum(ego_mass, vru_mass, speed):
    ego, other = plastic_delta_v(np.array([ego_mass]), np.array([vru_mass]), np.array([speed]))
    assert ego[0] * ego_mass == pytest.approx(other[0] * vru_mass, rel=1e-9, abs=1e-9)
    assert ego[0] + other[0] == pytest.approx(speed, rel=1e-9, abs=1e-12)  # the bodies leave together


def test_injury_curve_choices_are_the_schema_choices():
    assert MetricsSettings.model_fields["injury_risk_curve"].default == FATALITY_CURVES[0]
    for name in FATALITY_CURVES:
        assert MetricsSettings(injury_risk_curve=name).injury_risk_curve == name


def test_tefft_fatality_curve_is_chosen_in_yaml():
    tefft = row([vru(30.0, 0.0)], metrics={"injury_risk_curve": "tefft_2013"})
    assert tefft["fatality_risk"] == pytest.approx(float(risk(10.0, "tefft_2013")), abs=1e-4)


# ----------------------------------------------------------------------------------------------- surrogates


@pytest.fixture(scope="module")
def following() -> dict:
    """A VRU ahead at x = 20 moving away at 5 m/s, for 2 s: gap 17.25 - 5t, TTC 3.45 - t (TTC* = 3 s)."""
    return row([vru(20.0, 0.0, speed=5.0, heading=0.0)], duration=2.0, metrics={"tet_ttc_threshold_s": 3.0})


def test_drac_and_btn_peak_at_the_end_of_a_closing_run(following):
    # at t = 2: gap 7.25 m, closing speed 5 m/s -> DRAC = 5^2 / (2 * 7.25)
    assert following["peak_drac_mps2"] == pytest.approx(25 / 14.5, rel=1e-6)
    assert following["peak_drac_time_s"] == pytest.approx(2.0)
    assert following["peak_btn"] == pytest.approx(25 / 14.5 / 8.0, abs=1e-4)  # ego.max_decel_mps2 = 8
    assert following["min_ttc_s"] == pytest.approx(1.45, abs=1e-6)
    assert following["min_ttc_time_s"] == pytest.approx(2.0)


def test_tet_and_tit_integrate_the_ttc_below_the_threshold(following):
    # TTC <= 3 from t = 0.45 to 2: TET = 1.55 s, TIT = integral of (t - 0.45) dt = 1.55^2 / 2
    assert following["tet_s"] == pytest.approx(1.55, abs=1.5 * DT)
    assert following["tit_s2"] == pytest.approx(1.55**2 / 2, abs=2 * DT)


def test_lateral_clearance_while_passing_a_standing_pedestrian():
    passing = row([vru(30.0, 2.0)], duration=4.0)
    assert not passing["collided"]
    assert passing["min_lateral_clearance_m"] == pytest.approx(2.0 - W - R, abs=1e-9)  # 0.6 m
    # alongside from the first step end with centre x >= 30 - l, t >= 2.775
    assert passing["min_lateral_clearance_time_s"] == pytest.approx(2.78, abs=1e-9)
    assert passing["min_clearance_m"] == pytest.approx(0.6, abs=1e-9)
    assert passing["min_clearance_time_s"] == pytest.approx(2.78, abs=1e-9)


def test_pet_when_the_vru_crosses_first():
    # crossing at x = 30 from y = -5 at 2 m/s: in the corridor |y| <= 1.4 from 1.8 s to 3.2 s; the ego (centre
    # from x = -20) reaches the zone (x = 29.5) with its front at t = (29.5 - 2.25 + 20) / 10 = 4.725 s
    crossing = row([vru(30.0, -5.0, speed=2.0)], ego_x=-20.0, duration=6.0)
    assert not crossing["collided"]
    assert crossing["pet_s"] == pytest.approx(4.725 - 3.2, abs=1.5 * DT)


def test_pet_when_the_ego_passes_first():
    # the ego's rear passes the disc at x = 10 when its centre reaches 10 + 2.25 + 0.5: t = 1.275 s; the VRU
    # (from y = -11 at 2 m/s) enters the corridor at y = -1.4, t = 4.8 s
    behind = row([vru(10.0, -11.0, speed=2.0)], duration=6.0)
    assert behind["pet_s"] == pytest.approx(4.8 - 1.275, abs=1.5 * DT)


def test_pet_is_zero_on_a_collision_and_null_without_a_crossing(head_on):
    assert head_on["pet_s"] == 0.0
    assert row([vru(30.0, 3.0)], duration=2.0)["pet_s"] is None


def test_per_vru_minima_in_json_columns_and_parquet():
    vrus = [vru(20.0, 0.0, speed=5.0, heading=0.0), vru(15.0, 2.0)]
    data = minimal_scenario_dict()
    data["vrus"], data["sim"]["duration_s"] = vrus, 2.0
    run = simulate([scenario_from_mapping(data, "case.yaml")])
    summary = summary_rows(run)[0]
    # VRU 0: TTC 3.45 - t and clearance 17.25 - 5t, smallest at t = 2; VRU 1 alongside: gap 2 - 0.9 - 0.5
    assert summary["min_ttc_per_vru_s"] == [pytest.approx(1.45, abs=1e-6), None]
    assert summary["min_clearance_per_vru_m"] == [pytest.approx(7.25, abs=1e-6), pytest.approx(0.6, abs=1e-9)]
    assert summary["min_ttc_s"] == pytest.approx(1.45, abs=1e-6) and summary["min_clearance_m"] == pytest.approx(0.6)
    json.dumps(summary, allow_nan=False)
    columns = result_columns(run)
    assert columns["min_ttc_vru0_s"][0] == pytest.approx(1.45, abs=1e-6) and np.isnan(columns["min_ttc_vru1_s"][0])
    table = chunk_table({"variant": [0]}, {"variant": pa.int64()}, columns)
    assert table.column("min_clearance_vru1_m").type == pa.float64()
    assert table.column("min_ttc_vru1_s").null_count == 1


@settings(max_examples=8, deadline=None)
@given(st.floats(4.0, 16.0), st.floats(0.5, 5.0), st.floats(-1.5, 1.5))
def test_tet_and_tit_are_bounded(speed, threshold, offset):
    data = minimal_scenario_dict()
    data["ego"]["cruise_speed_mps"] = speed
    data["vrus"] = [vru(25.0, offset, speed=1.0, heading=0.0)]
    data["metrics"] = {"tet_ttc_threshold_s": threshold}
    summary = summary_rows(simulate([scenario_from_mapping(copy.deepcopy(data), "case.yaml")]))[0]
    assert 0.0 <= summary["tet_s"] <= summary["end_time_s"] + 1e-9
    assert 0.0 <= summary["tit_s2"] <= threshold * summary["tet_s"] + 1e-9


# ----------------------------------------------------------------------------------------------- validation


@pytest.mark.parametrize(
    ("where", "value", "path"),
    [
        (("ego", "mass_kg"), 0.0, "ego.mass_kg"),
        (("ego", "mass_kg"), 1e6, "ego.mass_kg"),
        (("vrus", 0, "mass_kg"), -1.0, "vrus[0].mass_kg"),
        (("metrics", "tet_ttc_threshold_s"), 0.0, "metrics.tet_ttc_threshold_s"),
        (("metrics", "tet_ttc_threshold_s"), 11.0, "metrics.tet_ttc_threshold_s"),
        (("metrics", "injury_risk_curve"), "kroyer", "metrics.injury_risk_curve"),
    ],
)
def test_bad_new_fields_are_named(where, value, path):
    data = minimal_scenario_dict()
    target = data
    for key in where[:-1]:
        target = target.setdefault(key, {}) if isinstance(key, str) else target[key]
    target[where[-1]] = value
    with pytest.raises(UserInputError) as info:
        scenario_from_mapping(data, "case.yaml")
    assert f"\n  {path}: " in str(info.value), str(info.value)


def test_bad_mass_exits_2_naming_the_field(tmp_path):
    path = tmp_path / "heavy.yaml"
    data = minimal_scenario_dict()
    data["vrus"][0]["mass_kg"] = 5000
    path.write_text(json.dumps(data), encoding="utf-8")
    result = CliRunner().invoke(app, ["run", str(path)], catch_exceptions=False)
    assert result.exit_code == 2, result.output
    assert "vrus[0].mass_kg" in result.output and "Traceback" not in result.output


def test_per_vru_rows_are_the_same_alone_and_in_a_batch_with_more_slots():
    one = minimal_scenario_dict()
    one["vrus"] = [vru(30.0, -5.0, speed=2.0)]
    one["ego"]["start"]["x_m"] = -20.0
    two = minimal_scenario_dict()
    two["vrus"] = [vru(20.0, 0.0, speed=5.0, heading=0.0), vru(15.0, 2.0)]
    scenarios = [scenario_from_mapping(data, "case.yaml") for data in (one, two)]
    batch = simulate(scenarios).metrics
    alone = simulate(scenarios[:1]).metrics
    for row_name in ("min_ttc_s", "min_clearance_m", "pet_s"):
        np.testing.assert_array_equal(batch.vru_row(row_name)[0, :1], alone.vru_row(row_name)[0], err_msg=row_name)
