"""Sweep specs, field paths, fast variants and the design: parsing, errors, determinism, distributions."""

from __future__ import annotations

import json
import math
import warnings
from pathlib import Path

import numpy as np
import pytest
import yaml
from hypothesis import given
from hypothesis import strategies as st

from conftest import PAPER_DIR
from vrusim.errors import UserInputError
from vrusim.scenario.loading import load_scenario
from vrusim.scenario.schema import Scenario
from vrusim.scenario.v2x import resolve_channel
from vrusim.sweep.design import make_design, preflight_rows, variant_seeds
from vrusim.sweep.field_paths import check_path, parse_path, with_values
from vrusim.sweep.plan import TEST_COLUMN, VariantBuilder, make_plan
from vrusim.sweep.spec import parse_parameter, spec_from_mapping

PEDESTRIAN = PAPER_DIR / "pedestrian_crossing.yaml"


def spec(parameters: dict, **fields):
    data = {"base": str(PEDESTRIAN), "parameters": parameters, **fields}
    return spec_from_mapping(data, "spec.yaml", Path("."))


@pytest.fixture(scope="module")
def base() -> Scenario:
    return load_scenario(PEDESTRIAN)


# --------------------------------------------------------------------------------------------- parameters


@pytest.mark.parametrize(
    ("value", "kind", "values"),
    [
        ([1, 2, 3], "grid", (1, 2, 3)),
        ({"values": ["ideal", "lossy"]}, "grid", ("ideal", "lossy")),
        ({"range": [10, 12, 0.5]}, "grid", (10.0, 10.5, 11.0, 11.5, 12.0)),
        ({"range": {"start": 0, "stop": 0.3, "step": 0.1}}, "grid", (0.0, 0.1, 0.2, 0.3)),
        ({"linspace": [0, 1, 3]}, "grid", (0.0, 0.5, 1.0)),
        ({"choice": [True, False]}, "choice", (True, False)),
    ],
)
def test_grid_and_choice_values(value, kind, values):
    parameter = parse_parameter("x", value)
    assert (parameter.kind, parameter.values) == (kind, values)


@pytest.mark.parametrize(
    ("value", "message"),
    [
        (3.0, "give a fixed value under `set`"),
        ([], "at least one value"),
        ({"uniform": [2, 1]}, "parameters.x.uniform: expected low < high"),
        ({"uniform": [1]}, "parameters.x.uniform: expected [low, high]"),
        ({"uniform": [0, "a"]}, "expected [low, high]"),
        ({"normal": [1, 0]}, "parameters.x.normal: expected std > 0"),
        ({"truncated_normal": [0, 1, 50, 60]}, "holds almost none"),
        ({"truncated_normal": {"mean": 0, "std": 1}}, "expected the keys mean, std, low, high"),
        ({"range": [0, 1, 0]}, "step > 0"),
        ({"linspace": [0, 1, 0]}, "count must be a whole number"),
        ({"choice": {"values": [1, 2], "weights": [1]}}, "2 weights, one per value"),
        ({"choice": {"values": [1, 2], "weights": [-1, 2]}}, "non-negative weights"),
        ({"gamma": [1, 2]}, "unknown kind 'gamma'"),
        ({"uniform": [0, 1], "normal": [0, 1]}, "expected a list of values or one of"),
    ],
)
def test_bad_parameters_name_the_entry(value, message):
    with pytest.raises(UserInputError, match=r"parameters\.x") as error:
        parse_parameter("x", value)
    assert message in str(error.value)


@pytest.mark.parametrize(
    ("data", "message"),
    [
        ({"parameters": {}}, "give exactly one of base"),
        ({"base": "a.yaml", "catalogue": {"scenarios": ["CPNA"]}, "parameters": {}}, "give exactly one of base"),
        ({"base": str(PEDESTRIAN), "samples": 0}, "samples: Input should be greater than or equal to 1"),
        ({"base": str(PEDESTRIAN), "sampels": 3}, "sampels: unknown field"),
        ({"base": str(PEDESTRIAN), "samples": True}, "samples: Input should be a valid integer, got true"),
        ({"base": str(PEDESTRIAN), "set": {"a": 1}, "parameters": {"a": [1, 2]}}, "set.a: a field is either fixed"),
        ({"base": str(PEDESTRIAN), "parameters": {"a": [1, 2]}, "samples": 10**8}, "exceed"),
    ],
)
def test_bad_spec_documents(data, message):
    with pytest.raises(UserInputError) as error:
        spec_from_mapping(data, "spec.yaml", Path("."))
    assert message in str(error.value)


# -------------------------------------------------------------------------------------------------- paths


def test_paths_parse_into_names_and_indices():
    assert parse_path("vrus[0].trigger.at_time_s") == ("vrus", 0, "trigger", "at_time_s")
    assert parse_path("obstacles[1][2].x") == ("obstacles", 1, 2, "x")
    with pytest.raises(UserInputError, match="not a field path"):
        parse_path("vrus..x")


@pytest.mark.parametrize(
    ("path", "message"),
    [
        ("ego.speed", "unknown field 'speed' in ego"),
        ("ego.cruise_speed", "did you mean cruise_speed_mps?"),
        ("vrus[2].top_speed_mps", "vrus has 1 element(s), no [2]"),
        ("vrus[0].brake.decel_mps2", "vrus[0].brake is not set in the base scenario"),
        ("ego.cruise_speed_mps.x", "is a value (15.0)"),
        ("ego[0]", "ego is not a list"),
        ("v2x.channel.loss.probability", "unknown field 'probability' in v2x.channel.loss"),
    ],
)
def test_unknown_paths_explain_the_step(base, path, message):
    with pytest.raises(UserInputError) as error:
        check_path(base, path)
    assert message in str(error.value)


def test_a_channel_profile_is_walked_as_its_specification(base):
    steps = check_path(base, "v2x.channel.latency_s")
    variant = with_values(base, [(steps, 0.25), (check_path(base, "v2x.channel.track_max_age_s"), 1.0)], "v")
    expected = resolve_channel("ideal").model_copy(update={"latency_s": 0.25, "track_max_age_s": 1.0})
    assert variant.v2x.channel == expected


def _slow_variant(base: Scenario, cruise: float, vru_speed: float, start_s: float, latency: float) -> Scenario:
    data = base.model_dump()
    data["ego"]["cruise_speed_mps"] = cruise
    data["vrus"][0]["top_speed_mps"] = vru_speed
    data["vrus"][0]["trigger"]["at_time_s"] = start_s
    data["v2x"]["enabled"] = True
    data["v2x"]["channel"] = {**resolve_channel("ideal").model_dump(), "latency_s": latency, "track_max_age_s": 2.0}
    return Scenario.model_validate(data)


@given(
    cruise=st.floats(0.0, 40.0),
    vru_speed=st.floats(0.0, 10.0),
    start_s=st.floats(0.0, 5.0),
    latency=st.floats(0.0, 1.0),
)
def test_copy_on_write_variant_equals_a_full_validation(base, cruise, vru_speed, start_s, latency):
    paths = ["ego.cruise_speed_mps", "vrus[0].top_speed_mps", "vrus[0].trigger.at_time_s", "v2x.enabled"]
    paths += ["v2x.channel.latency_s", "v2x.channel.track_max_age_s"]
    values = [cruise, vru_speed, start_s, True, latency, 2.0]
    fast = with_values(base, [(check_path(base, p), v) for p, v in zip(paths, values, strict=True)], "v")
    assert fast == _slow_variant(base, cruise, vru_speed, start_s, latency)
    assert base.ego.cruise_speed_mps == 15.0 and not base.v2x.enabled  # the base is untouched


def test_a_bad_value_names_the_field(base):
    with pytest.raises(UserInputError, match=r"ego.cruise_speed_mps: Input should be greater than or equal to 0"):
        with_values(base, [(check_path(base, "ego.cruise_speed_mps"), -1.0)], "variant 3")
    with pytest.raises(UserInputError, match=r"vrus.0. starts overlapping the ego vehicle"):
        with_values(base, [(check_path(base, "vrus[0].start"), [-50.0, -1.75])], "variant 3")
    with pytest.raises(UserInputError, match=r"ego.cruise_speed_mps: Input should be a valid number, got 'fast'"):
        with_values(base, [(check_path(base, "ego.cruise_speed_mps"), "fast")], "variant 3")


# ------------------------------------------------------------------------------------------------- design


def test_grid_dimensions_vary_slowest_first_with_samples_innermost():
    plan = make_plan(spec({"ego.cruise_speed_mps": [10, 20], "v2x.enabled": [False, True]}, samples=3))
    design = make_design(plan)
    assert plan.variants == 12 and plan.grid_points == 4
    assert design["ego.cruise_speed_mps"].tolist() == [10] * 6 + [20] * 6
    assert design["v2x.enabled"].tolist() == ([False] * 3 + [True] * 3) * 2
    assert design["variant"].tolist() == list(range(12))
    assert len(set(design["seed"].tolist())) == 12


def test_draws_are_reproducible_and_do_not_depend_on_other_parameters():
    one = make_design(make_plan(spec({"ego.cruise_speed_mps": {"uniform": [10, 20]}}, samples=500, seed=9)))
    again = make_design(make_plan(spec({"ego.cruise_speed_mps": {"uniform": [10, 20]}}, samples=500, seed=9)))
    more = make_design(
        make_plan(
            spec(
                {"vrus[0].top_speed_mps": {"normal": [1.5, 0.1]}, "ego.cruise_speed_mps": {"uniform": [10, 20]}},
                samples=500,
                seed=9,
            )
        )
    )
    other_seed = make_design(make_plan(spec({"ego.cruise_speed_mps": {"uniform": [10, 20]}}, samples=500, seed=10)))
    np.testing.assert_array_equal(one["ego.cruise_speed_mps"], again["ego.cruise_speed_mps"])
    np.testing.assert_array_equal(one["ego.cruise_speed_mps"], more["ego.cruise_speed_mps"])
    np.testing.assert_array_equal(one["seed"], more["seed"])
    assert not np.array_equal(one["ego.cruise_speed_mps"], other_seed["ego.cruise_speed_mps"])


def test_distributions_have_their_moments_and_supports():
    n = 40_000
    design = make_design(
        make_plan(
            spec(
                {
                    "ego.cruise_speed_mps": {"uniform": [10, 20]},
                    "vrus[0].top_speed_mps": {"truncated_normal": {"mean": 1.5, "std": 0.5, "low": 1.0, "high": 3.0}},
                    "vrus[0].trigger.at_time_s": {"normal": [2.0, 0.3]},
                    "v2x.channel": {"choice": {"values": ["ideal", "lossy"], "weights": [3, 1]}},
                },
                samples=n,
            )
        )
    )
    uniform = design["ego.cruise_speed_mps"]
    assert uniform.min() >= 10 and uniform.max() < 20 and abs(uniform.mean() - 15) < 0.05
    truncated = design["vrus[0].top_speed_mps"]
    assert truncated.min() >= 1.0 and truncated.max() <= 3.0
    # mean of N(1.5, 0.5) truncated to [1, 3]: mu + sigma (phi(a) - phi(b)) / (Phi(b) - Phi(a))
    a, b = (1.0 - 1.5) / 0.5, (3.0 - 1.5) / 0.5
    phi = lambda z: math.exp(-z * z / 2) / math.sqrt(2 * math.pi)  # noqa: E731
    cdf = lambda z: 0.5 * (1 + math.erf(z / math.sqrt(2)))  # noqa: E731
    assert abs(truncated.mean() - (1.5 + 0.5 * (phi(a) - phi(b)) / (cdf(b) - cdf(a)))) < 0.01
    normal = design["vrus[0].trigger.at_time_s"]
    assert abs(normal.mean() - 2.0) < 0.01 and abs(normal.std() - 0.3) < 0.01
    assert abs(np.mean(design["v2x.channel"] == "ideal") - 0.75) < 0.01


def test_variant_seeds_are_distinct_non_negative_and_keyed_by_master_seed():
    seeds = variant_seeds(1, 100_000)
    assert seeds.min() >= 0 and len(np.unique(seeds)) == seeds.size
    assert not np.array_equal(seeds[:10], variant_seeds(2, 10))
    np.testing.assert_array_equal(seeds[:10], variant_seeds(1, 10))


def test_a_swept_sim_seed_is_the_variant_seed():
    design = make_design(make_plan(spec({"sim.seed": [5, 6, 7]})))
    assert design["seed"].tolist() == [5, 6, 7]


def test_preflight_rows_cover_extremes_and_every_discrete_value():
    plan = make_plan(
        spec({"v2x.channel": ["ideal", "lossy", "bursty"], "ego.cruise_speed_mps": {"uniform": [5, 25]}}, samples=2000)
    )
    design = make_design(plan)
    rows = preflight_rows(design, plan, first=10)
    speeds = design["ego.cruise_speed_mps"][rows]
    assert speeds.min() == design["ego.cruise_speed_mps"].min() and speeds.max() == design["ego.cruise_speed_mps"].max()
    assert set(design["v2x.channel"][rows]) == {"ideal", "lossy", "bursty"}
    assert plan.variants - 1 in rows and len(rows) < 30


def test_catalogue_protocol_selects_the_edition_and_names_itself_when_unknown():
    data = {"catalogue": {"scenarios": ["CPRA-Cs"], "protocol": "2023"}, "parameters": {}}
    plan = make_plan(spec_from_mapping(data, "spec.yaml", Path(".")))
    assert len(plan.tests) == 6
    data["catalogue"]["protocol"] = "1999"
    with pytest.raises(UserInputError, match=r"catalogue\.protocol: unknown edition '1999'"):
        make_plan(spec_from_mapping(data, "spec.yaml", Path(".")))


def test_catalogue_base_adds_the_test_dimension():
    data = {
        "catalogue": {"scenarios": ["CPNA-25"], "protocol": "2023"},
        "parameters": {"vrus[0].top_speed_mps": [1.0, 2.0]},
    }
    plan = make_plan(spec_from_mapping(data, "spec.yaml", Path(".")))
    design = make_design(plan)
    tests = list(plan.tests)
    assert len(tests) >= 5 and plan.variants == 2 * len(tests)
    assert design[TEST_COLUMN].tolist()[:2] == [tests[0], tests[0]]
    variants = VariantBuilder(plan).build({k: v.tolist() for k, v in design.items()}, range(2))
    assert [v.vrus[0].top_speed_mps for v in variants] == [1.0, 2.0]
    assert variants[0].name == tests[0]


def test_spec_file_base_is_relative_to_the_spec(tmp_path):
    (tmp_path / "sub").mkdir()
    path = tmp_path / "sub" / "s.yaml"
    path.write_text(yaml.safe_dump({"base": "../ped.yaml", "parameters": {"ego.cruise_speed_mps": [10]}}))
    (tmp_path / "ped.yaml").write_text(PEDESTRIAN.read_text())
    from vrusim.sweep.spec import load_spec

    assert make_plan(load_spec(path)).variants == 1


# -------------------------------------------------------------------------------------------- correlation

CORRELATED = {
    "ego.cruise_speed_mps": {"uniform": [10, 20]},
    "vrus[0].top_speed_mps": {"truncated_normal": {"mean": 1.5, "std": 0.5, "low": 1.0, "high": 3.0}},
    "vrus[0].trigger.at_time_s": {"normal": [2.0, 0.3]},
    "v2x.channel": {"choice": {"values": ["ideal", "lossy"], "weights": [3, 1]}},
    "v2x.channel.latency_s": {"uniform": [0.0, 1.0]},
}


def _normal_scores(column: np.ndarray) -> np.ndarray:
    """Φ⁻¹ of the ranks: undoes any monotone marginal transform, leaving the copula's normals."""
    from scipy.special import ndtri

    ranks = np.argsort(np.argsort(column)) + 1
    return ndtri(ranks / (column.size + 1))


def test_correlated_draws_keep_their_marginals_and_get_the_correlation():
    n = 40_000
    correlation = [
        {"between": ["ego.cruise_speed_mps", "vrus[0].top_speed_mps"], "rho": 0.6},
        {"between": ["vrus[0].trigger.at_time_s", "ego.cruise_speed_mps"], "rho": -0.4},
        {"between": ["v2x.channel", "vrus[0].trigger.at_time_s"], "rho": 0.5},
    ]
    design = make_design(make_plan(spec(CORRELATED, samples=n, correlation=correlation)))
    independent = make_design(make_plan(spec(CORRELATED, samples=n)))
    speed, vru, start = (
        design["ego.cruise_speed_mps"],
        design["vrus[0].top_speed_mps"],
        design["vrus[0].trigger.at_time_s"],
    )
    # each keeps its own distribution (the copula maps each through its inverse CDF): compare with exact quantiles
    from scipy.special import ndtr, ndtri

    q = np.linspace(0.05, 0.95, 10)
    lo, hi = ndtr(-1.0), ndtr(3.0)  # N(1.5, 0.5) truncated to [1, 3], standardised ends
    exact = {
        "ego.cruise_speed_mps": 10 + 10 * q,
        "vrus[0].top_speed_mps": 1.5 + 0.5 * ndtri(lo + q * (hi - lo)),
        "vrus[0].trigger.at_time_s": 2.0 + 0.3 * ndtri(q),
    }
    for path, quantiles in exact.items():
        np.testing.assert_allclose(np.quantile(design[path], q), quantiles, atol=0.03 * design[path].std())
    assert speed.min() >= 10 and speed.max() < 20 and vru.min() >= 1.0 and vru.max() <= 3.0
    assert abs(np.mean(design["v2x.channel"] == "ideal") - 0.75) < 0.01
    # the underlying normals carry the given correlations; uncorrelated pairs stay uncorrelated
    assert np.corrcoef(_normal_scores(speed), _normal_scores(vru))[0, 1] == pytest.approx(0.6, abs=0.02)
    assert np.corrcoef(_normal_scores(speed), start)[0, 1] == pytest.approx(-0.4, abs=0.02)
    assert np.corrcoef(_normal_scores(vru), start)[0, 1] == pytest.approx(0.0, abs=0.02)
    # the choice parameter: "lossy" (the upper quarter of its uniform) goes with late starts
    lossy = design["v2x.channel"] == "lossy"
    assert start[lossy].mean() > start[~lossy].mean() + 0.2
    # a parameter named in no pair keeps exactly its independent draws
    np.testing.assert_array_equal(design["v2x.channel.latency_s"], independent["v2x.channel.latency_s"])


def test_correlated_design_is_reproducible_and_recorded_in_the_plan():
    from vrusim.sweep.runner import plan_from_manifest

    correlation = [{"between": ["ego.cruise_speed_mps", "vrus[0].top_speed_mps"], "rho": 0.3}]
    plan = make_plan(spec(CORRELATED, samples=50, correlation=correlation))
    np.testing.assert_array_equal(
        make_design(plan)["vrus[0].top_speed_mps"], make_design(plan)["vrus[0].top_speed_mps"]
    )
    assert plan.describe()["correlations"] == [["ego.cruise_speed_mps", "vrus[0].top_speed_mps", 0.3]]
    manifest = json.loads(json.dumps({"plan": plan.describe(), "plan_sha256": plan.digest()}))
    assert plan_from_manifest(manifest) == plan
    # without correlations the description (and so the digest of existing sweeps) has no such key
    assert "correlations" not in make_plan(spec(CORRELATED, samples=50)).describe()


@pytest.mark.parametrize(
    ("correlation", "message"),
    [
        ([{"between": ["ego.cruise_speed_mps", "sensor.range_m"], "rho": 0.5}], "'sensor.range_m' is not a random"),
        ([{"between": ["ego.cruise_speed_mps", "ego.cruise_speed_mps"], "rho": 0.5}], "two different parameters"),
        (
            [
                {"between": ["ego.cruise_speed_mps", "vrus[0].top_speed_mps"], "rho": 0.5},
                {"between": ["vrus[0].top_speed_mps", "ego.cruise_speed_mps"], "rho": 0.2},
            ],
            "correlation[1].between: the pair ego.cruise_speed_mps, vrus[0].top_speed_mps is given twice",
        ),
        (
            [{"between": ["ego.cruise_speed_mps", "vrus[0].top_speed_mps"], "rho": 1.0}],
            "correlation[0].rho: Input should be less than 1",
        ),
        ([{"between": ["ego.cruise_speed_mps"], "rho": 0.5}], "correlation[0].between[1]: Field required"),
        (
            [
                {"between": ["ego.cruise_speed_mps", "vrus[0].top_speed_mps"], "rho": 0.9},
                {"between": ["ego.cruise_speed_mps", "vrus[0].trigger.at_time_s"], "rho": 0.9},
                {"between": ["vrus[0].top_speed_mps", "vrus[0].trigger.at_time_s"], "rho": -0.9},
            ],
            "cannot hold together",
        ),
    ],
)
def test_bad_correlations_name_the_entry(correlation, message):
    parameters = {**CORRELATED, "sensor.range_m": [10.0, 20.0]}
    with pytest.raises(UserInputError) as error:
        spec(parameters, correlation=correlation)
    assert message in str(error.value)


# --------------------------------------------------------------------------------------------- overlapping paths


@pytest.mark.parametrize(
    ("parameters", "fixed", "names"),
    [
        (
            {"vrus[0].top_speed_mps": [0.5, 2.5], "vrus[00].top_speed_mps": [1.5]},
            {},
            ["'vrus[0].top_speed_mps'", "'vrus[00].top_speed_mps'", "same field"],
        ),
        (
            {"ego.cruise_speed_mps": [5, 20], "ego": [{"cruise_speed_mps": 12}]},
            {},
            ["'ego'", "'ego.cruise_speed_mps'", "overlap", "overwrite"],
        ),
        ({"v2x.channel.latency_s": [0.1], "v2x.channel": ["ideal"]}, {}, ["'v2x.channel'", "overlap", "first"]),
        (
            {"vrus[00].top_speed_mps": [1.5]},
            {"vrus[0].top_speed_mps": 1.0},
            ["set.vrus[0].top_speed_mps", "parameters"],
        ),
    ],
)
def test_parameters_naming_one_field_twice_are_refused(parameters, fixed, names):
    with pytest.raises(UserInputError) as caught:
        spec(parameters, set=fixed)
    for name in names:
        assert name in str(caught.value)


def test_a_parent_swept_before_its_field_is_overridden_by_the_field(base):
    ego = base.ego.model_dump(mode="json") | {"cruise_speed_mps": 12.0}
    plan = make_plan(spec({"ego": [ego], "ego.cruise_speed_mps": [5.0, 20.0]}))
    design = make_design(plan)
    variants = VariantBuilder(plan).build({k: v.tolist() for k, v in design.items()}, range(2))
    assert [v.ego.cruise_speed_mps for v in variants] == [5.0, 20.0]


# --------------------------------------------------------------------------------------------- extreme numbers


@pytest.mark.parametrize(
    ("value", "message"),
    [
        ({"range": [0, 1.0e300, 1.0e-300]}, "range: its values"),
        ({"range": [-1.0e308, 1.0e308, 1.0e308]}, "stop - start to be a finite number"),
        ({"linspace": [-1.0e308, 1.0e308, 5]}, "stop - start to be a finite number"),
        ({"uniform": [-1.0e308, 1.0e308]}, "high - low to be a finite number"),
    ],
)
def test_ends_too_far_apart_are_refused_by_name(value, message):
    with pytest.raises(UserInputError) as caught:
        parse_parameter("vrus[0].trigger.at_time_s", value)
    assert "parameters.vrus[0].trigger.at_time_s." in str(caught.value) and message in str(caught.value)


def test_huge_choice_weights_are_scaled_and_equal_weights_stay_equal():
    parameter = parse_parameter("x", {"choice": {"values": [1, 2], "weights": [1.0e308, 1.0e308]}})
    assert parameter.weights == (0.5, 0.5)
    assert parse_parameter("x", {"choice": {"values": [1, 2], "weights": [3, 1]}}).weights == (0.75, 0.25)


def test_a_seed_beyond_int64_draws_no_warning():
    plan = make_plan(spec({"sim.seed": {"uniform": [0, 1.0e30]}}, samples=3))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        make_design(plan)


@pytest.mark.parametrize(
    ("fields", "message"),
    [
        ({"name": "a\x01b"}, r"name: .*control character U\+0001 \(character 2\)"),
        ({"name": "two\nlines"}, r"name: .*control character U\+000A"),
        ({"description": "x\ud800y"}, r"description: .*lone surrogate U\+D800"),
    ],
)
def test_free_text_of_a_spec_that_no_output_can_carry_is_refused(fields, message):
    """A spec's name and description reach the terminal, the manifest and the HTML report, as a scenario's do."""
    with pytest.raises(UserInputError, match=message):
        spec({"ego.cruise_speed_mps": [10.0]}, **fields)
    assert spec({"ego.cruise_speed_mps": [10.0]}, name="ok", description="two\n\tlines").name == "ok"
