"""Determinism and batch independence: a variant's results do not depend on what else is in its batch."""

from __future__ import annotations

import copy
import warnings

import numpy as np
import pytest

from vrusim.engine import accumulators as streaming
from vrusim.engine.accumulators import RunMetrics
from vrusim.engine.simulate import simulate
from vrusim.scenario.loading import scenario_from_mapping

BATCH_SIZE = 1000
DURATION_S = 12.0

SCRATCH_FIELDS = {"prev_actuator", "prev_clearance", "prev_speed"}
"""RunMetrics' step-to-step working state, not results: it keeps being updated for a variant that has already
stopped while the rest of its batch runs on, so it legitimately differs between a solo run and a batch run."""


def metric_arrays(metrics: RunMetrics) -> dict[str, np.ndarray]:
    """Every per-variant array field of RunMetrics (first axis = variant), by name.

    Plain array attributes, plus the accumulator rows that RunMetrics may keep in one packed `values` array
    and expose as attributes (listed in `streaming.FIELDS`).
    """
    size = metrics.params.size
    names = {name for name, value in vars(metrics).items() if isinstance(value, np.ndarray)}
    names.discard("values")  # the packed [field, B] store itself; its rows are read by name below
    names |= set(getattr(streaming, "FIELDS", ()))
    out = {name: np.asarray(getattr(metrics, name)) for name in sorted(names) if not name.startswith("_")}
    for name, value in out.items():
        assert value.shape[:1] == (size,), f"{name}: shape {value.shape}, batch of {size}"
    return out


def variant_transitions(metrics: RunMetrics, b: int) -> list[tuple[float, int, int]]:
    return [(t, old, new) for t, index, old, new in metrics.transitions if index == b]


def second_vru() -> dict:
    """A cyclist crossing from the far side: used by a few variants so the batch has K = 2 slots."""
    return {
        "type": "cyclist",
        "start": {"x_m": 30.0, "y_m": 9.0},
        "heading_deg": -90.0,
        "top_speed_mps": 4.0,
        "trigger": {"at_time_s": 1.0},
    }


def build_variants(paper: dict, count: int, seed: int = 20250101) -> list:
    rng = np.random.default_rng(seed)
    variants = []
    for i in range(count):
        data = copy.deepcopy(paper)
        data["name"] = f"variant-{i}"
        data["sim"]["duration_s"] = DURATION_S
        data["ego"]["cruise_speed_mps"] = round(float(rng.uniform(10.0, 20.0)), 3)
        data["vrus"][0]["trigger"] = {"at_time_s": round(float(rng.uniform(0.0, 2.5)), 3)}
        data["vrus"][0]["top_speed_mps"] = round(float(rng.uniform(1.0, 3.0)), 3)
        data["v2x"]["enabled"] = bool(rng.random() < 0.5)
        if i % 50 == 7:
            data["vrus"].append(second_vru())
        variants.append(scenario_from_mapping(data))
    return variants


@pytest.fixture(scope="module")
def variants(paper_pedestrian_dict):
    return build_variants(paper_pedestrian_dict, BATCH_SIZE)


@pytest.fixture(scope="module")
def big_batch(variants):
    return simulate(variants)


def pick(metrics: RunMetrics, variants, category: str) -> int:
    """The first variant of the batch in a category, so the solo comparisons cover different outcomes."""
    v2x = np.array([s.v2x.enabled for s in variants])
    two = np.array([len(s.vrus) == 2 for s in variants])
    masks = {
        "first": np.arange(len(variants)) == 0,
        "last": np.arange(len(variants)) == len(variants) - 1,
        "collided": metrics.collided & ~v2x & ~two,
        "avoided-v2x": ~metrics.collided & v2x & ~two,
        "avoided-no-v2x": ~metrics.collided & ~v2x & ~two,
        "two-vrus": two & ~v2x,
        "two-vrus-v2x": two & v2x,
    }
    mask = masks[category]
    if not mask.any():
        pytest.skip(f"no variant in category {category}")
    return int(np.argmax(mask))


def test_batch_has_the_intended_mix(big_batch, variants):
    m = big_batch.metrics
    assert big_batch.params.vru_slots == 2
    assert 0 < m.collided.sum() < BATCH_SIZE
    v2x = np.array([s.v2x.enabled for s in variants])
    assert 0 < v2x.sum() < BATCH_SIZE
    assert len({s.ego.cruise_speed_mps for s in variants}) > 900


CATEGORIES = ["first", "last", "collided", "avoided-v2x", "avoided-no-v2x", "two-vrus", "two-vrus-v2x"]


@pytest.fixture(scope="module")
def solo_runs(big_batch, variants):
    """Solo run of the chosen variant of each category (computed once, shared by the exact and tolerant
    tests)."""
    cache: dict[str, tuple[int, RunMetrics]] = {}

    def get(category: str) -> tuple[int, RunMetrics]:
        if category not in cache:
            b = pick(big_batch.metrics, variants, category)
            cache[category] = (b, simulate([variants[b]]).metrics)
        return cache[category]

    return get


def _compared_fields(in_batch: RunMetrics, alone: RunMetrics):
    batch_fields, alone_fields = metric_arrays(in_batch), metric_arrays(alone)
    assert batch_fields.keys() == alone_fields.keys()
    names = sorted(batch_fields.keys() - SCRATCH_FIELDS)
    assert len(names) >= 20
    return [(name, batch_fields[name], alone_fields[name]) for name in names]


@pytest.mark.parametrize("category", CATEGORIES)
def test_variant_alone_matches_variant_in_batch(big_batch, solo_runs, category):
    """Same outcome alone and in a batch of 1,000: discrete results exact, real numbers to round-off."""
    b, alone = solo_runs(category)
    for name, batch_values, alone_values in _compared_fields(big_batch.metrics, alone):
        mine, solo = batch_values[b], alone_values[0]
        if np.issubdtype(np.asarray(mine).dtype, np.floating):
            assert np.array_equal(np.isnan(mine), np.isnan(solo)), f"variant {b}: {name}"
            assert np.array_equal(np.isinf(mine), np.isinf(solo)), f"variant {b}: {name}"
            assert np.allclose(mine, solo, rtol=1e-12, atol=1e-12, equal_nan=True), f"variant {b}: {name}"
        else:
            assert np.array_equal(mine, solo), f"variant {b} ({category}): {name} {mine!r} != {solo!r}"
    mine_t, solo_t = variant_transitions(big_batch.metrics, b), variant_transitions(alone, 0)
    assert [(o, n) for _, o, n in mine_t] == [(o, n) for _, o, n in solo_t]
    assert [t for t, _, _ in mine_t] == pytest.approx([t for t, _, _ in solo_t], abs=1e-9)


@pytest.mark.parametrize(
    "category",
    CATEGORIES,
)
def test_variant_alone_bitwise_equals_variant_in_batch(big_batch, solo_runs, category):
    """Bit-for-bit: every result array of RunMetrics and the variant's transitions."""
    b, alone = solo_runs(category)
    for name, batch_values, alone_values in _compared_fields(big_batch.metrics, alone):
        mine, solo = batch_values[b], alone_values[0]
        assert np.array_equal(mine, solo, equal_nan=True), f"variant {b} ({category}): {name} {mine!r} != {solo!r}"
    assert variant_transitions(big_batch.metrics, b) == variant_transitions(alone, 0)


def test_same_run_twice_is_identical(variants):
    subset = variants[:60]
    assert sum(len(s.vrus) == 2 for s in subset) >= 2
    first = simulate(subset, trace=True)
    second = simulate(subset, trace=True)
    assert first.steps == second.steps
    a, b = metric_arrays(first.metrics), metric_arrays(second.metrics)
    assert a.keys() == b.keys()
    for name in a:
        assert np.array_equal(a[name], b[name], equal_nan=True), name
    assert first.metrics.transitions == second.metrics.transitions
    assert first.trace.keys() == second.trace.keys()
    for name in first.trace:
        assert np.array_equal(first.trace[name], second.trace[name], equal_nan=True), name


def test_batch_order_does_not_matter(variants):
    subset = variants[:40]
    order = np.random.default_rng(3).permutation(len(subset))
    forward = simulate(subset).metrics
    shuffled = simulate([subset[i] for i in order]).metrics
    fa, fb = metric_arrays(forward), metric_arrays(shuffled)
    for name in sorted(fa.keys() - SCRATCH_FIELDS):
        assert np.array_equal(fa[name][order], fb[name], equal_nan=True), name
    for new_index, old_index in enumerate(order):
        assert variant_transitions(shuffled, new_index) == variant_transitions(forward, int(old_index))


def _far_vrus(count: int) -> list[dict]:
    return [{"type": "pedestrian", "start": [500.0 + 10.0 * k, 50.0], "heading_deg": 90.0} for k in range(count)]


def test_mixed_vru_counts_with_a_stopped_ego_emit_no_warning():
    """Padded VRU slots (trigger at t = inf) next to an ego at standstill: no inf * 0 RuntimeWarning."""
    scenarios = [
        scenario_from_mapping(
            {
                "name": f"k{k}",
                "ego": {"start": [0, 0], "cruise_speed_mps": 0.0},
                "planner": {"name": "none"},
                "vrus": _far_vrus(k),
                "sim": {"duration_s": 0.1},
            }
        )
        for k in (1, 2)
    ]
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        simulate(scenarios)


def _still_ego(vrus: list[dict], name: str = "solo", **sim) -> object:
    return scenario_from_mapping(
        {
            "name": name,
            "ego": {"start": [0, 0], "cruise_speed_mps": 0.0},
            "planner": {"name": "none"},
            "vrus": vrus,
            "sim": {"duration_s": 3.0, **sim},
        }
    )


def test_vru_trajectory_bitwise_independent_of_other_paths_in_batch():
    """Minimal reproduction: a cyclist's trajectory alone vs next to a variant with a 10 m VRU path."""
    cyclist = _still_ego([{"type": "cyclist", "start": [30.0, 9.0], "heading_deg": -90.0, "top_speed_mps": 4.0}])
    other = _still_ego([{"type": "pedestrian", "start": [40.0, -20.0], "path": [[40.0, -10.0]]}], "other")
    solo = simulate([cyclist], trace=True).trace
    pair = simulate([cyclist, other], trace=True).trace
    # to round-off they agree (so the motion itself is right) ...
    np.testing.assert_allclose(solo["vru_y_m"][:, 0, 0], pair["vru_y_m"][:, 0, 0], rtol=0, atol=1e-12)
    # ... but not bit for bit
    assert np.array_equal(solo["vru_y_m"][:, 0, 0], pair["vru_y_m"][:, 0, 0])


def test_parallel_kernels_match_serial(monkeypatch, variants):
    """Large batches run multi-threaded kernels: results must be bit-identical to the serial ones."""
    from vrusim import kernels

    subset = variants[:64]
    serial = simulate(subset)
    monkeypatch.setattr(kernels, "PARALLEL_MIN_BATCH", 1)
    parallel = simulate(subset)
    assert np.array_equal(serial.metrics.values, parallel.metrics.values, equal_nan=True)
    assert serial.metrics.transitions == parallel.metrics.transitions
    assert np.array_equal(serial.metrics.collided, parallel.metrics.collided)


def _imperfect(paper: dict, planner: str) -> list:
    """Variants with a realistic sensor and V2X channel (state the engine must carry when it drops variants)."""
    data = copy.deepcopy(paper)
    data["planner"] = {"name": planner} if planner != "fsm" else data["planner"]
    data["sensor"].update(latency_s=0.05, detection_probability=0.9, position_sigma_m=0.1, frame_rate_hz=20)
    data["v2x"]["channel"] = {
        "generation": {"mode": "periodic", "rate_hz": 10},
        "latency_s": 0.1,
        "jitter_s": 0.02,
        "loss": {"model": "bernoulli", "probability": 0.2},
    }
    return build_variants(data, 120, seed=7)


@pytest.mark.parametrize("planner", ["fsm", "aeb", "predictive", "none"])
def test_dropping_stopped_variants_changes_no_result(monkeypatch, paper_pedestrian_dict, planner):
    """The engine drops stopped variants from its working set: results bit-identical to stepping them all."""
    from vrusim.engine import simulate as engine

    subset = _imperfect(paper_pedestrian_dict, planner)
    dropped = simulate(subset)
    monkeypatch.setattr(engine, "COMPACT_BELOW", 0.0)
    kept = simulate(subset)
    end = kept.metrics.end_time_s
    assert (end < end.max()).mean() > 0.5  # most variants stop before the last: the working set shrinks
    assert dropped.steps == kept.steps
    a, b = metric_arrays(dropped.metrics), metric_arrays(kept.metrics)
    assert a.keys() == b.keys()
    for name in sorted(a.keys() - SCRATCH_FIELDS):
        assert np.array_equal(a[name], b[name], equal_nan=True), name
    assert dropped.metrics.transitions == kept.metrics.transitions
    assert np.array_equal(dropped.metrics.first_mode_s, kept.metrics.first_mode_s, equal_nan=True)
