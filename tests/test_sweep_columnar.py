"""Columnar sweeps: batches packed from design columns equal `pack` of the per-variant scenarios exactly, column
checks flag every variant the per-variant build refuses (whose message is then the per-variant one)."""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from typing import Any

import numpy as np
import pyarrow as pa
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from conftest import PAPER_DIR, REPO_ROOT
from vrusim.errors import UserInputError
from vrusim.sim.params import pack
from vrusim.sweep import chunk
from vrusim.sweep.columnar import ColumnarPacker
from vrusim.sweep.design import design_rows, make_design
from vrusim.sweep.field_columns import WRITERS
from vrusim.sweep.plan import SweepPlan, VariantBuilder, make_plan
from vrusim.sweep.runner import run_sweep
from vrusim.sweep.spec import spec_from_mapping
from vrusim.sweep.store import SweepStore

CHANNEL = {
    "generation": {"mode": "periodic", "rate_hz": 10},
    "latency_s": 0.1,
    "jitter_s": 0.05,
    "track_max_age_s": 1.5,
    "loss": {"model": "bernoulli", "probability": 0.1},
}
SET = {"v2x.enabled": True, "v2x.channel": CHANNEL, "sim.duration_s": 6.0}
POINT = {"x_m": 18.0, "y_m": -1.75}
TRIGGERS = {
    "at_time_s": {"at_time_s": 0.3},
    "ego_distance_m": {"ego_distance_m": 30.0, "point": POINT},
    "ego_time_to_arrival_s": {"ego_time_to_arrival_s": 2.0, "point": POINT},
    "ego_route_m": {"ego_route_m": 20.0},
    "ego_speed_below_mps": {"ego_speed_below_mps": 5.0},
    "ego_speed_above_mps": {"ego_speed_above_mps": 5.0},
    "ego_standstill_s": {"ego_standstill_s": 1.0},
}

FIELDS: dict[str, tuple[dict[str, Any], dict[str, Any]]] = {
    # path: (extra `set`, distribution within the field's rules)
    "sim.seed": ({}, {"choice": [0, 1, 7, 2**62, 2**63 - 1]}),
    "sim.duration_s": ({}, {"uniform": [1.0, 8.0]}),
    "ego.cruise_speed_mps": ({}, {"uniform": [0.0, 30.0]}),
    "ego.initial_speed_mps": ({}, {"uniform": [0.0, 30.0]}),
    "ego.max_accel_mps2": ({}, {"uniform": [0.5, 5.0]}),
    "ego.max_decel_mps2": ({}, {"uniform": [1.0, 10.0]}),
    "ego.max_jerk_mps3": ({}, {"uniform": [1.0, 40.0]}),
    "ego.actuator_lag_s": ({}, {"uniform": [0.0, 0.5]}),
    "ego.mass_kg": ({}, {"uniform": [100.0, 5000.0]}),
    "ego.tracking.lateral_gain_per_m2": ({}, {"uniform": [0.1, 1.0]}),
    "ego.tracking.heading_gain_per_m": ({}, {"uniform": [0.5, 2.0]}),
    "sensor.range_m": ({"sensor.lighting": "night"}, {"uniform": [5.0, 60.0]}),
    "sensor.night_range_factor": ({"sensor.lighting": "night"}, {"uniform": [0.1, 1.0]}),
    "sensor.latency_s": ({}, {"choice": [0.0, 0.005, 0.015, 0.1, 0.25]}),
    "sensor.detection_probability": ({}, {"choice": [1.0, 0.5, 0.9]}),
    "sensor.position_sigma_m": ({}, {"choice": [0.0, 0.2]}),
    "sensor.velocity_sigma_mps": ({}, {"choice": [0.0, 0.3]}),
    "v2x.comm_range_m": ({}, {"uniform": [10.0, 100.0]}),
    "v2x.coverage_range_m": ({}, {"uniform": [10.0, 100.0]}),
    "v2x.channel.loss.probability": ({}, {"uniform": [0.0, 1.0]}),
    "v2x.channel.latency_s": ({}, {"uniform": [0.0, 1.4]}),
    "v2x.channel.jitter_s": ({}, {"uniform": [0.0, 1.4]}),
    "v2x.channel.track_max_age_s": ({}, {"uniform": [0.2, 3.0]}),
    "v2x.channel.rsu_position_sigma_m": ({}, {"choice": [0.0, 0.5]}),
    "v2x.channel.rsu_speed_sigma_mps": ({}, {"choice": [0.0, 0.5]}),
    "metrics.tet_ttc_threshold_s": ({}, {"uniform": [0.5, 3.0]}),
    "vrus[0].top_speed_mps": ({}, {"uniform": [0.0, 3.0]}),
    "vrus[0].max_accel_mps2": ({}, {"uniform": [0.5, 3.0]}),
    "vrus[0].speed_time_constant_s": ({}, {"uniform": [0.0, 1.0]}),
    "vrus[0].initial_speed_mps": ({}, {"uniform": [0.0, 2.0]}),
    "vrus[0].mass_kg": ({}, {"uniform": [1.0, 1000.0]}),
    **{
        f"vrus[0].trigger.{name}": ({"vrus[0].trigger": trigger}, {"uniform": [0.0, 5.0]})
        for name, trigger in TRIGGERS.items()
    },
}
IDEAL = {"v2x.channel": {"generation": {"mode": "every_step"}, "track_max_age_s": 0.0}}
"""A channel that is ideal until a swept field makes it not (checks the refreshed `ideal` flags)."""


def plan_of(parameters: dict[str, Any], overrides: dict[str, Any], samples: int = 30, seed: int = 5) -> SweepPlan:
    data = {
        "base": str(PAPER_DIR / "pedestrian_crossing.yaml"),
        "set": {k: v for k, v in {**SET, **overrides}.items() if k not in parameters},
        "parameters": parameters,
        "samples": samples,
        "seed": seed,
    }
    return make_plan(spec_from_mapping(data, "sweep.yaml", REPO_ROOT))


def assert_same(a: Any, b: Any, where: str = "params") -> None:
    """Equal values of equal types, arrays equal with their dtypes (NaN equal to NaN)."""
    assert type(a) is type(b), f"{where}: {type(a).__name__} != {type(b).__name__}"
    if isinstance(a, np.ndarray):
        assert a.dtype == b.dtype and a.shape == b.shape, f"{where}: {a.dtype}{a.shape} != {b.dtype}{b.shape}"
        assert np.array_equal(a, b, equal_nan=a.dtype.kind == "f"), where
    elif dataclasses.is_dataclass(a):
        for f in dataclasses.fields(a):
            assert_same(getattr(a, f.name), getattr(b, f.name), f"{where}.{f.name}")
    elif isinstance(a, list | tuple):
        assert len(a) == len(b), where
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            assert_same(x, y, f"{where}[{i}]")
    elif isinstance(a, Mapping):
        assert list(a) == list(b), where
        for key in a:
            assert_same(a[key], b[key], f"{where}[{key!r}]")
    elif hasattr(a, "__dict__"):
        assert_same(vars(a), vars(b), where)
    else:
        assert a == b, f"{where}: {a!r} != {b!r}"


def columnar_and_scenarios(plan: SweepPlan, start: int = 0, stop: int | None = None):
    """The packer's groups and the per-variant scenarios of the design rows [start, stop)."""
    design = make_design(plan)
    rows = design_rows(design, start, plan.variants if stop is None else stop)
    builder = VariantBuilder(plan)
    packer = ColumnarPacker.of(plan, builder.bases)
    assert packer is not None, "every field of the plan has a writer"
    assert packer.flagged(rows).size == 0
    count = rows["variant"].size
    scenarios = builder.build(chunk._lists(rows, np.arange(count)), range(count))
    return packer.groups(rows), scenarios


def test_every_writer_is_tested():
    tested = {next((w for w in WRITERS if w.pattern.fullmatch(path)), None) for path in FIELDS}
    assert tested == set(WRITERS)


@pytest.mark.parametrize("path", FIELDS)
@pytest.mark.parametrize("ideal", [False, True], ids=["channel", "ideal-channel"])
def test_packed_columns_equal_pack_of_the_variants(path, ideal):
    extra, distribution = FIELDS[path]
    if ideal and path == "v2x.channel.loss.probability":
        pytest.skip("a Bernoulli loss is never ideal")
    overrides = {**extra, **(IDEAL if ideal else {})}
    if path.startswith("v2x.channel.") and ideal:
        overrides["v2x.channel"] = {**IDEAL["v2x.channel"], "track_max_age_s": 3.0}
    if path in ("v2x.channel.latency_s", "v2x.channel.jitter_s"):
        overrides["v2x.channel"] = {**overrides.get("v2x.channel", CHANNEL), "track_max_age_s": 3.0}
        if not ideal:
            overrides["v2x.channel"]["jitter_s" if path.endswith("latency_s") else "latency_s"] = 0.0
    distribution = {"choice": [0.0, 0.0, 0.4, 1.2]} if ideal and "channel" in path else distribution
    plan = plan_of({path: distribution}, overrides)
    ((rows, _, params),), scenarios = columnar_and_scenarios(plan)
    assert np.array_equal(rows, np.arange(len(scenarios)))
    assert_same(params, pack(scenarios))


def test_several_fields_at_once_and_an_int_grid():
    parameters = {
        "ego.cruise_speed_mps": [10, 12, 15],  # ints into a float field
        "ego.initial_speed_mps": {"uniform": [0.0, 10.0]},
        "v2x.channel.latency_s": {"uniform": [0.0, 0.6]},
        "v2x.channel.jitter_s": {"uniform": [0.0, 0.6]},
        "vrus[0].top_speed_mps": {"truncated_normal": [1.5, 0.3, 0.8, 2.5]},
        "vrus[0].trigger.at_time_s": {"uniform": [0.0, 1.5]},
        "sim.duration_s": {"uniform": [2.0, 7.0]},
    }
    plan = plan_of(parameters, {}, samples=20)
    ((_, _, params),), scenarios = columnar_and_scenarios(plan, 5, 47)
    assert_same(params, pack(scenarios))


def test_a_catalogue_sweep_packs_each_test_as_its_scenarios():
    data = {
        "catalogue": {"scenarios": ["CPNA", "CBLA"], "night": True},
        "parameters": {"ego.max_decel_mps2": {"uniform": [5.0, 9.0]}, "sim.seed": {"choice": [1, 2, 3]}},
        "samples": 3,
        "seed": 2,
    }
    plan = make_plan(spec_from_mapping(data, "sweep.yaml", REPO_ROOT))
    start, stop = 2, min(plan.variants, 40)
    groups, scenarios = columnar_and_scenarios(plan, start, stop)
    by_group: dict[tuple[str, float], list[int]] = {}
    for row, scenario in enumerate(scenarios):
        by_group.setdefault((scenario.planner.name, scenario.sim.dt_s), []).append(row)
    assert len(groups) == len(by_group)
    for (rows, planner, params), ((name, _), expected) in zip(groups, by_group.items(), strict=True):
        assert planner == name and rows.tolist() == expected
        assert_same(params, pack([scenarios[r] for r in expected]))


def test_a_field_without_a_writer_builds_every_variant():
    plan = plan_of({"vrus[0].heading_deg": {"uniform": [60.0, 120.0]}}, {})
    assert ColumnarPacker.of(plan, VariantBuilder(plan).bases) is None
    plan = plan_of({"vrus[0].trigger.ego_route_m": {"uniform": [0.0, 5.0]}}, {})  # the base triggers on time
    assert ColumnarPacker.of(plan, VariantBuilder(plan).bases) is None


# --- column checks ----------------------------------------------------------------------------------------------

NUMBERS = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True, width=64),
    st.floats(min_value=-2.0, max_value=12.0),
    st.sampled_from([0.0, -0.0, 1.0, 1e9, 150.0, 150.0000001, 10.0, 1.5, 0.8]),
)
CHECKED = [
    "ego.cruise_speed_mps",
    "ego.max_decel_mps2",
    "vrus[0].top_speed_mps",
    "vrus[0].trigger.at_time_s",
    "v2x.channel.latency_s",
    "v2x.channel.loss.probability",
    "v2x.channel.track_max_age_s",
    "sim.duration_s",
    "ego.mass_kg",
    "sensor.detection_probability",
]


def _message(action) -> str | None:
    try:
        action()
    except UserInputError as error:
        return str(error)
    return None


def _check_columns(plan: SweepPlan, columns: dict[str, list[Any]]) -> None:
    """A design of these columns: the flagged rows hold every row the per-variant build refuses, and the
    columnar path's message is the per-variant one."""
    count = len(next(iter(columns.values())))
    design = make_design(plan)
    rows = {name: column[:count].copy() for name, column in design.items()}
    for name, values in columns.items():
        rows[name] = np.array(values, dtype=float)
    builder = VariantBuilder(plan)
    packer = ColumnarPacker.of(plan, builder.bases)
    assert packer is not None
    flagged = set(packer.flagged(rows).tolist())
    lists = chunk._lists(rows, np.arange(count))
    for row in range(count):
        if row not in flagged:
            builder.build(lists, [row])  # passes
    expected = _message(lambda: builder.build(lists, range(count)))
    task = chunk.ChunkTask(plan, plan.digest(), 0, rows, {})
    chunk._BUILDERS.clear()
    actual = _message(lambda: chunk.batch_columns(task)) if expected is not None else expected
    assert actual == expected


@pytest.mark.parametrize("path", CHECKED)
@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(values=st.lists(NUMBERS, min_size=1, max_size=6))
def test_column_checks_give_the_per_variant_messages(path, values):
    plan = plan_of({path: {"uniform": [0.5, 1.0]}}, {"v2x.channel": {**CHANNEL, "jitter_s": 0.2}}, samples=6)
    _check_columns(plan, {path: values})


@settings(max_examples=20, deadline=None)
@given(
    latency=st.lists(st.floats(min_value=0.0, max_value=3.0), min_size=4, max_size=4),
    jitter=st.lists(st.floats(min_value=0.0, max_value=3.0), min_size=4, max_size=4),
    age=st.lists(st.floats(min_value=0.0, max_value=5.0), min_size=4, max_size=4),
)
def test_cross_field_checks_give_the_per_variant_messages(latency, jitter, age):
    parameters = {f"v2x.channel.{name}": {"uniform": [0.0, 1.0]} for name in ("latency_s", "jitter_s")}
    parameters["v2x.channel.track_max_age_s"] = {"uniform": [2.0, 3.0]}
    plan = plan_of(parameters, {}, samples=4)
    _check_columns(
        plan,
        {"v2x.channel.latency_s": latency, "v2x.channel.jitter_s": jitter, "v2x.channel.track_max_age_s": age},
    )


def test_a_bad_draw_names_the_variant_as_before(tmp_path):
    data = {"ego.cruise_speed_mps": {"normal": [5.0, 10.0]}}
    plan = plan_of(data, {}, samples=400)
    design = make_design(plan)
    rows = design_rows(design, 300, 400)  # past the preflight rows
    task = chunk.ChunkTask(plan, plan.digest(), 3, rows, {})
    builder = VariantBuilder(plan)
    expected = _message(lambda: builder.build(chunk._lists(rows, np.arange(100)), range(100)))
    assert expected is not None and expected.startswith("variant 3")
    chunk._BUILDERS.clear()
    assert _message(lambda: chunk.batch_columns(task)) == expected


# --- whole sweeps ---------------------------------------------------------------------------------------------------


def _sweep(folder, monkeypatch, columnar: bool) -> pa.Table:
    import yaml

    data = {
        "name": "columnar",
        "base": str(PAPER_DIR / "pedestrian_crossing.yaml"),
        "set": SET,
        "parameters": {
            "ego.cruise_speed_mps": {"truncated_normal": [15.0, 1.5, 10.0, 20.0]},
            "vrus[0].top_speed_mps": {"truncated_normal": [1.5, 0.3, 0.8, 2.5]},
            "vrus[0].trigger.at_time_s": {"uniform": [0.0, 1.5]},
            "v2x.channel.latency_s": {"uniform": [0.0, 1.0]},
            "v2x.channel.loss.probability": {"uniform": [0.0, 0.9]},
        },
        "samples": 60,
        "seed": 11,
        "batch_size": 25,
    }
    (folder / "spec.yaml").write_text(yaml.safe_dump(data))
    from vrusim.sweep.spec import load_spec

    if not columnar:
        monkeypatch.setattr(chunk.ColumnarPacker, "of", classmethod(lambda cls, plan, bases: None))
    chunk._BUILDERS.clear()
    run_sweep(load_spec(folder / "spec.yaml"), folder / "out", workers=1)
    monkeypatch.undo()
    chunk._BUILDERS.clear()
    return SweepStore(folder / "out").read()


def test_a_columnar_sweep_stores_the_rows_of_the_per_variant_one(tmp_path, monkeypatch):
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    columnar = _sweep(tmp_path / "a", monkeypatch, True)
    per_variant = _sweep(tmp_path / "b", monkeypatch, False)
    assert columnar.num_rows == 60 and columnar.equals(per_variant)
