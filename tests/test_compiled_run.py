"""The compiled run of the built-in planners (`engine.compiled_run`) gives exactly the per-step path's results."""

from __future__ import annotations

import copy
import dataclasses
import importlib
import itertools
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import REPO_ROOT, deep_update
from vrusim.engine import compiled_run
from vrusim.engine.accumulators import ACCUMULATORS
from vrusim.engine.simulate import BatchRun, simulate
from vrusim.engine.trace_recorder import TRACE_COLUMNS
from vrusim.errors import UserInputError
from vrusim.ncap.build import build_test
from vrusim.ncap.grid import select
from vrusim.paper.cases import paper_scenarios
from vrusim.planners.base import HoldSpeedPlanner
from vrusim.planners.fsm import FsmPlanner
from vrusim.planners.registry import make_planner
from vrusim.scenario.loading import load_scenario, scenario_from_mapping
from vrusim.sim.compaction import take
from vrusim.sim.params import BatchParams, pack
from vrusim.sim.sensing.registry import register_sensor_model, unregister_sensor_model

PLANNERS = ("fsm", "none", "aeb", "predictive")
RESULT_ROWS = [i for i, row in enumerate(ACCUMULATORS) if row.reduce != "carry"]


def _as_planner(batch: BatchParams, name: str) -> BatchParams:
    """The batch driven by planner `name` with its default parameters."""
    if name == "fsm":
        return batch
    return dataclasses.replace(batch, planner_names=[name] * batch.size, planner_params=[{}] * batch.size)


def assert_identical(compiled: BatchRun, per_step: BatchRun) -> None:
    """Every streamed result, transition and the step count are the same, bit for bit (NaN where NaN). The
    `carry` rows are not results: the per-step path goes on updating them for stopped variants until it drops
    them from its working set, the compiled run stops a variant at once."""
    a, b = compiled.metrics, per_step.metrics
    np.testing.assert_array_equal(a.values[RESULT_ROWS], b.values[RESULT_ROWS], strict=True)
    np.testing.assert_array_equal(a._per_vru, b._per_vru, strict=True)
    np.testing.assert_array_equal(a.collided, b.collided, strict=True)
    np.testing.assert_array_equal(a.first_mode_s, b.first_mode_s, strict=True)
    assert a.transitions == b.transitions
    assert compiled.steps == per_step.steps
    assert compiled.mode_names == per_step.mode_names


def both_paths(batch: BatchParams) -> tuple[BatchRun, BatchRun]:
    return simulate(batch, compiled=True), simulate(batch, compiled=False)


@pytest.fixture(scope="module")
def paper_batch() -> BatchParams:
    return pack([scenario for _, _, scenario in paper_scenarios()])


@pytest.mark.parametrize("planner", PLANNERS)
def test_paper_cases_identical(paper_batch, planner):
    compiled, per_step = both_paths(_as_planner(paper_batch, planner))
    assert_identical(compiled, per_step)
    assert compiled.metrics.values.size and np.isfinite(compiled.metrics.min_clearance_m).all()


@pytest.mark.parametrize("planner", PLANNERS)
@pytest.mark.parametrize("case", range(3))
def test_one_variant_identical(planner, case):
    """A batch of one variant (`vrusim run`): its state arrays are C- and Fortran-ordered at once."""
    one = pack([paper_scenarios()[case][2]])
    compiled, per_step = both_paths(_as_planner(one, planner))
    assert_identical(compiled, per_step)


def assert_same_trace(compiled: BatchRun, per_step: BatchRun) -> None:
    """The same columns in the same order, each of the same dtype and shape and bit for bit equal."""
    assert compiled.trace is not None and per_step.trace is not None
    assert list(compiled.trace) == list(per_step.trace) == list(TRACE_COLUMNS)
    for name, column in compiled.trace.items():
        other = per_step.trace[name]
        assert (column.dtype, column.shape) == (other.dtype, other.shape), name
        assert column.tobytes() == other.tobytes(), name


@pytest.mark.parametrize("planner", PLANNERS)
@pytest.mark.parametrize("case", range(3))
@pytest.mark.parametrize("v2x", [False, True])
def test_one_variant_trace_recorded_compiled_is_the_per_step_trace(planner, case, v2x):
    """One variant's trace (`vrusim.run` of one scenario, `vrusim run --trace`) is recorded inside the compiled
    step, row by row: the per-step path's trace, bit for bit, and the same results."""
    scenario = paper_scenarios()[case][2]
    one = pack([scenario.model_copy(update={"v2x": scenario.v2x.model_copy(update={"enabled": v2x})})])
    compiled = simulate(_as_planner(one, planner), trace=True, compiled=True)
    per_step = simulate(_as_planner(one, planner), trace=True, compiled=False)
    assert_same_trace(compiled, per_step)
    assert_identical(compiled, per_step)
    assert len(compiled.trace["t_s"]) == compiled.steps


@pytest.mark.parametrize("planner", PLANNERS)
@pytest.mark.parametrize("v2x", [False, True])
def test_batch_trace_recorded_compiled_is_the_per_step_trace(paper_batch, planner, v2x):
    """A traced batch whose variants stop at different steps: as on the per-step path, the stopped ones go on
    moving (and are recorded) until the last one stops, without adding to their results or transitions."""
    batch = dataclasses.replace(_as_planner(paper_batch, planner), v2x_enabled=np.full(paper_batch.size, v2x))
    compiled = simulate(batch, trace=True, compiled=True)
    per_step = simulate(batch, trace=True, compiled=False)
    assert_same_trace(compiled, per_step)
    assert_identical(compiled, per_step)
    assert len(set(compiled.metrics.end_time_s.tolist())) > 1  # the variants stop at different steps


@pytest.mark.parametrize("planner", PLANNERS)
def test_a_traced_run_of_no_step_gives_the_same_empty_columns_on_both_paths(paper_batch, planner):
    """A batch made by hand with no step (`n_steps` = 0; `pack` never makes one): both paths give every trace
    column without a row (the per-step path gave no column at all)."""
    batch = dataclasses.replace(_as_planner(paper_batch, planner), n_steps=0)
    compiled = simulate(batch, trace=True, compiled=True)
    per_step = simulate(batch, trace=True, compiled=False)
    assert_same_trace(compiled, per_step)
    assert_identical(compiled, per_step)
    assert compiled.steps == 0 and compiled.trace["vru_x_m"].shape == (0, batch.size, batch.vru_slots)


class _WideModes(HoldSpeedPlanner):
    """A plug-in planner whose mode array is int64 (the built-in planners' is int8)."""

    mode_names = ("holding", "other")

    def reset(self, batch: BatchParams) -> None:
        super().reset(batch)
        self.mode = np.zeros(batch.size, dtype=np.int64)


def test_a_run_of_no_step_keeps_a_plug_in_planners_mode_dtype(paper_batch):
    """The zero-step trace's `planner_mode` has the dtype a recorded step gives it: the planner's (was int8)."""
    batch = _as_planner(paper_batch, "none")
    recorded = simulate(dataclasses.replace(batch, n_steps=1), planner=_WideModes(), trace=True).trace
    empty = simulate(dataclasses.replace(batch, n_steps=0), planner=_WideModes(), trace=True).trace
    assert recorded["planner_mode"].dtype == np.int64
    assert (empty["planner_mode"].dtype, empty["planner_mode"].shape) == (np.int64, (0, paper_batch.size))


@pytest.mark.parametrize("compiled", [True, False])
def test_an_empty_packed_batch_is_refused_as_pack_refuses_no_scenario(paper_batch, compiled):
    """A packed batch cut to no variant gets `pack([])`'s message, not an IndexError, on both paths."""
    empty = take(paper_batch, np.array([], dtype=np.int64))
    with pytest.raises(UserInputError, match="at least one scenario"):
        simulate(empty, compiled=compiled)
    with pytest.raises(UserInputError, match="at least one scenario"):
        pack([])


def test_empty_trace_columns_are_those_a_run_with_a_driver_and_a_door_records():
    """`trace_columns` has the recorder's columns, dtypes and shapes, the driver's and the door's included."""
    tests = select(["CBDA", "CPMFC"], night=False, protocol="2026")
    batch = pack([build_test(test, "fsm").scenario for test in tests[:1] + tests[-1:]])
    assert batch.driver.has.any() and batch.door.has.any()
    recorded = simulate(dataclasses.replace(batch, n_steps=1), trace=True).trace
    empty = simulate(dataclasses.replace(batch, n_steps=0), trace=True).trace
    assert list(recorded)[-2:] == ["driver_accel_mps2", "door_angle_rad"]
    assert list(empty) == list(recorded)
    for name, column in recorded.items():
        assert (empty[name].dtype, empty[name].shape) == (column.dtype, (0, *column.shape[1:])), name


@pytest.mark.parametrize("planner", PLANNERS)
def test_trace_with_realistic_sensor_and_channel(paper_pedestrian_dict, planner):
    """Detections from a sensor that misses and lags, and V2X ages from a lossy, jittery channel (NaN: none),
    for one variant and for a batch of six."""
    scenarios = [
        scenario_from_mapping(_realistic(paper_pedestrian_dict, seed, 11.0 + seed), f"v{seed}") for seed in range(6)
    ]
    for batch in (pack(scenarios[3:4]), pack(scenarios)):
        compiled = simulate(_as_planner(batch, planner), trace=True, compiled=True)
        per_step = simulate(_as_planner(batch, planner), trace=True, compiled=False)
        assert_same_trace(compiled, per_step)
        assert_identical(compiled, per_step)
        ages = compiled.trace["vru_v2x_age_s"]
        assert np.isnan(ages).any() and (ages > 0.0).any()


def test_one_variant_trace_of_euro_ncap_tests_with_obstructions():
    """Euro NCAP tests whose obstruction occludes the sensor, each traced alone."""
    tests = select(["CPNC", "CBNAO"], night=True, protocol="2026")
    for test in tests[:: max(1, len(tests) // 4)]:
        one = pack([build_test(test, "fsm", v2x=True).scenario])
        assert one.obstacles.x_m.shape[1] > 0
        assert_same_trace(simulate(one, trace=True, compiled=True), simulate(one, trace=True, compiled=False))


@pytest.mark.parametrize("planner", PLANNERS)
def test_one_variant_trace_of_two_vrus(paper_pedestrian_dict, planner):
    """Two pedestrians: the VRU columns per slot, clearance and TTC the smaller of the two."""
    data = copy.deepcopy(paper_pedestrian_dict)
    second = copy.deepcopy(data["vrus"][0])
    second.update(start={"x_m": 26.0, "y_m": 6.0}, heading_deg=-90, trigger={"at_time_s": 1.0})
    data["vrus"].append(second)
    one = pack([scenario_from_mapping(data, "two")])
    assert one.vru_slots == 2
    compiled = simulate(_as_planner(one, planner), trace=True, compiled=True)
    assert_same_trace(compiled, simulate(_as_planner(one, planner), trace=True, compiled=False))
    assert compiled.trace["vru_x_m"].shape[2] == 2


_KERNEL_VERSIONS = """
from vrusim.api.compiling import _run_briefly, _warm_up_scenarios
from vrusim.engine import compiled_run
counts = []
for planner, kernel in compiled_run._KERNELS.items():
    scenarios = _warm_up_scenarios(planner)
    for batch in (scenarios, scenarios[:1], scenarios[1:2], scenarios[:3]):
        _run_briefly(batch, compiled=True)
    counts.append(len(kernel.signatures))
print(counts)
"""


def test_batches_of_one_and_many_variants_share_one_kernel_version():
    """A kernel compiled by `vrusim compile` (a batch of every bundled scenario) serves `vrusim run` (one
    variant): numba types a one-variant state array as C-ordered, so variant-major arrays keep room for two."""
    done = subprocess.run([sys.executable, "-c", _KERNEL_VERSIONS], capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "[1, 1, 1, 1]"


def test_variant_major_arrays_keep_room_for_two_variants():
    """Variant-major arrays keep room for two variants and are Fortran-ordered; the others are as they were."""
    many = compiled_run._state_array((6,), 5, 2, True)
    assert many.shape == (6, 5, 2) and many.flags.f_contiguous and not many.flags.c_contiguous
    one = compiled_run._state_array((3,), 1, 1, True, np.inf)
    assert one.shape == (3, 2, 1) and not one.flags.c_contiguous and np.isinf(one).all()
    assert compiled_run._state_array((7,), 1, 1, False).shape == (7, 1, 1)
    rows = np.arange(12.0).reshape(4, 3)
    copy = compiled_run._state_copy(rows, True)
    np.testing.assert_array_equal(copy[:, :3], rows)
    assert copy.flags.f_contiguous
    assert compiled_run._state_copy(rows, False) is rows
    assert set(compiled_run.VARIANT_MAJOR) == set(compiled_run._KERNELS)


@given(size=st.integers(1, 20_000), threads=st.integers(1, 8))
def test_chunk_order_covers_every_variant_once_and_starts_the_threads_far_apart(size, threads):
    order = compiled_run.chunk_order(size, threads)
    ranked = sorted(order)
    assert ranked[0][0] == 0 and ranked[-1][1] == size
    assert all(stop == next_first for (_, stop), (next_first, _) in itertools.pairwise(ranked))
    assert all(stop - first >= compiled_run.MIN_CHUNK for first, stop in ranked[:-1])
    # the chunks taken together, one a thread, start the threads' runs: a run's length apart
    together = min(threads, len(order))
    run_length = len(order) // threads
    starts = [first for first, _ in order[:together]]
    chunk = ranked[0][1] - ranked[0][0]
    assert starts == sorted(starts)
    assert all(b - a >= run_length * chunk for a, b in itertools.pairwise(starts))


def test_chunk_order_of_a_sweep_batch_on_two_threads():
    """The sweep's batch of 2,500 on two threads: 16 chunks of 157, taken in turn from the two halves."""
    order = compiled_run.chunk_order(2500, 2)
    assert order[:4] == [(0, 157), (1256, 1413), (157, 314), (1413, 1570)]
    assert order[-2:] == [(1099, 1256), (2355, 2500)]


def test_a_run_over_chunks_on_two_threads_is_the_one_thread_run(paper_pedestrian_dict):
    """Which thread runs which variants does not change results: 300 varied variants in chunks of 64."""
    import numba

    if numba.config.NUMBA_NUM_THREADS < 2:
        pytest.skip("needs two numba threads")
    scenarios = []
    for i in range(300):
        data = deep_update(copy.deepcopy(paper_pedestrian_dict), {"ego": {"cruise_speed_mps": 8.0 + i * 0.04}})
        scenarios.append(scenario_from_mapping(data, f"v{i}"))
    batch = pack(scenarios)
    before = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        alone = simulate(batch, compiled=True)
        numba.set_num_threads(2)
        together = simulate(batch, compiled=True)
    finally:
        numba.set_num_threads(before)
    assert_identical(together, alone)


@pytest.mark.parametrize("planner", ["fsm", "aeb"])
def test_euro_ncap_grid_identical(planner):
    tests = select(["CPNC", "CPTA", "CBLA"], night=True, protocol="2026")
    batch = pack([build_test(test, planner, v2x=True).scenario for test in tests[::3]])
    assert batch.obstacles.x_m.shape[1] > 0  # the grid's obstruction occludes the sensor: covered as well
    compiled, per_step = both_paths(batch)
    assert_identical(compiled, per_step)
    assert compiled.metrics.collided.any() or np.isfinite(compiled.metrics.first_sensor_s).any()


def _realistic(paper_pedestrian_dict: dict, seed: int, speed_mps: float) -> dict:
    data = copy.deepcopy(paper_pedestrian_dict)
    return deep_update(
        data,
        {
            "sim": {"seed": seed},
            "ego": {"cruise_speed_mps": speed_mps},
            "sensor": {"latency_s": 0.1, "detection_probability": 0.8, "position_sigma_m": 0.2},
            "v2x": {
                "enabled": True,
                "channel": {
                    "generation": {"mode": "periodic", "rate_hz": 10},
                    "latency_s": 0.1,
                    "jitter_s": 0.05,
                    "track_max_age_s": 1.5,
                    "loss": {"model": "bernoulli", "probability": 0.3},
                },
            },
        },
    )


@pytest.mark.parametrize("planner", PLANNERS)
def test_realistic_sensor_and_channel_identical(paper_pedestrian_dict, planner):
    scenarios = [
        scenario_from_mapping(_realistic(paper_pedestrian_dict, seed, 11.0 + seed), f"v{seed}") for seed in range(6)
    ]
    compiled, per_step = both_paths(_as_planner(pack(scenarios), planner))
    assert_identical(compiled, per_step)
    assert np.isfinite(compiled.metrics.first_v2x_s).any()


@settings(max_examples=6, deadline=None)
@given(
    speeds=st.lists(st.floats(5.0, 22.0), min_size=1, max_size=5),
    walk_mps=st.floats(0.5, 3.0),
    start_s=st.floats(0.0, 2.0),
    v2x=st.booleans(),
)
def test_varied_pedestrian_crossings_identical(paper_pedestrian_dict, speeds, walk_mps, start_s, v2x):
    scenarios = []
    for i, speed in enumerate(speeds):
        data = deep_update(
            copy.deepcopy(paper_pedestrian_dict),
            {"ego": {"cruise_speed_mps": speed}, "v2x": {"enabled": v2x}},
        )
        data["vrus"][0].update(top_speed_mps=walk_mps, trigger={"at_time_s": start_s})
        scenarios.append(scenario_from_mapping(data, f"v{i}"))
    compiled, per_step = both_paths(pack(scenarios))
    assert_identical(compiled, per_step)


def test_more_transitions_than_room_run_again_compiled_with_room(paper_batch, monkeypatch):
    """A variant that changes mode more often than the first compiled run has room for: the run is repeated,
    compiled, with room for the most any variant made (not per step)."""
    reference = simulate(paper_batch, compiled=False)
    most = max(np.bincount([row[1] for row in reference.metrics.transitions]))
    assert most > 1
    monkeypatch.setattr(compiled_run, "TRANSITIONS_PER_VARIANT", 1)
    rooms: list[int] = []
    run_once = compiled_run._run_once
    monkeypatch.setattr(compiled_run, "_run_once", lambda *args: rooms.append(args[3]) or run_once(*args))
    monkeypatch.setattr(importlib.import_module("vrusim.engine.simulate"), "BatchStepper", None)  # no per-step run
    assert_identical(simulate(paper_batch), reference)
    assert rooms == [1, most]


def test_transitions_beyond_the_buffer_limit_run_per_step(paper_batch, monkeypatch):
    reference = simulate(paper_batch, compiled=False)
    monkeypatch.setattr(compiled_run, "TRANSITIONS_PER_VARIANT", 1)
    monkeypatch.setattr(compiled_run, "TRANSITION_BUFFER_BYTES", 1)
    fsm = make_planner("fsm")
    fsm.reset(paper_batch)
    assert compiled_run.run_compiled(paper_batch, fsm, len(fsm.mode_names)) is None
    assert_identical(simulate(paper_batch), reference)


def test_what_takes_the_per_step_path(paper_batch):
    fsm = make_planner("fsm")
    assert compiled_run.compiled_support(paper_batch, fsm, None, trace=False) is None
    assert compiled_run.compiled_support(paper_batch, fsm, None, trace=True) is None  # traces: compiled too

    class Braking(HoldSpeedPlanner):  # a subclass may act differently: never compiled
        pass

    assert "Braking" in compiled_run.compiled_support(paper_batch, Braking(), None, trace=False)
    wrapped = make_planner("fsm")  # an instance whose act is not the class's: its act must run
    wrapped.act = lambda observation: np.full(observation.ego_speed_mps.shape, -3.0)
    assert "act is replaced" in compiled_run.compiled_support(paper_batch, wrapped, None, trace=False)
    one = pack([paper_scenarios()[0][2]])
    assert (simulate(one, planner=wrapped, trace=True).trace["ego_command_mps2"] == -3.0).all()
    traced = simulate(paper_batch, trace=True, compiled=True)
    assert_identical(simulate(paper_batch), simulate(paper_batch, compiled=False))
    untraced = simulate(paper_batch).metrics.values
    np.testing.assert_array_equal(traced.metrics.values[RESULT_ROWS], untraced[RESULT_ROWS], strict=True)


def test_a_planner_class_whose_act_was_replaced_runs_per_step(monkeypatch):
    """A built-in planner class whose `act` was replaced (a mock, instrumentation) is not what its compiled step
    computes: traced or not, the replacement runs."""
    one = pack([paper_scenarios()[0][2]])
    monkeypatch.setattr(FsmPlanner, "act", lambda self, observation: np.full(observation.ego_speed_mps.shape, -2.0))
    assert "replaced on the class" in compiled_run.compiled_support(one, make_planner("fsm"), None, trace=True)
    traced = simulate(one, trace=True)
    assert (traced.trace["ego_command_mps2"] == -2.0).all()
    assert_identical(simulate(one), simulate(one, compiled=False))
    with pytest.raises(ValueError, match="replaced on the class"):
        simulate(one, compiled=True)


def test_a_plug_in_sensor_model_runs_per_step(paper_batch):
    """A registered sensor model (docs/models.md, "Adding a sensor model") is not computed by the compiled step:
    the run goes per step, so the plug-in decides what is detected."""

    class Blind:  # detects nothing
        def reset(self, params):
            pass

        def observe(self, step, t_s, visible, truth):
            return np.zeros_like(visible), truth

        def age_s(self, step, dt_s):
            return None

    register_sensor_model("blind", lambda params: True, Blind)
    try:
        assert "'blind'" in compiled_run.compiled_support(paper_batch, make_planner("fsm"), None, trace=False)
        blind = simulate(paper_batch)
        traced = simulate(paper_batch, trace=True)
        with pytest.raises(ValueError, match="plug-in sensor model 'blind'"):
            simulate(paper_batch, compiled=True)
    finally:
        unregister_sensor_model("blind")
    assert np.isnan(blind.metrics.first_sensor_s).all() and np.isnan(traced.metrics.first_sensor_s).all()
    assert np.isfinite(simulate(paper_batch).metrics.first_sensor_s).any()  # the ideal sensor sees them


def test_an_aeb_planner_after_a_compiled_run_holds_its_last_warnings():
    """The planner's `warning` after a run is what its own `act` left: the last step's FCW of each variant."""
    bundled = sorted((REPO_ROOT / "scenarios").glob("*/*.yaml"))  # two of them end warning
    batch = _as_planner(pack([load_scenario(path) for path in bundled]), "aeb")
    compiled, per_step = make_planner("aeb"), make_planner("aeb")
    simulate(batch, planner=compiled, trace=True, compiled=True)
    simulate(batch, planner=per_step, trace=True, compiled=False)
    np.testing.assert_array_equal(compiled.mode, per_step.mode)
    np.testing.assert_array_equal(compiled.warning, per_step.warning)
    assert compiled.warning.any()


def test_variants_with_drivers_or_doors_run_per_step_and_the_others_compiled(monkeypatch):
    tests = select(["CBDA", "CPMFC", "CPNA", "CBLA"], night=True, protocol="2026")
    batch = pack([build_test(test, "fsm").scenario for test in tests[::2]])
    low_speed = batch.driver.has | batch.door.has
    assert low_speed.any() and not low_speed.all()
    assert "drivers or doors" in compiled_run.compiled_support(batch, make_planner("fsm"), None, trace=False)
    compiled_sizes = []
    run_compiled = compiled_run.run_compiled

    def counted(part, planner, mode_count):
        compiled_sizes.append(part.size)
        return run_compiled(part, planner, mode_count)

    monkeypatch.setattr("vrusim.engine.simulate.run_compiled", counted)
    split = simulate(batch, planner=make_planner("fsm"))
    assert compiled_sizes == [int((~low_speed).sum())]  # the variants without a driver or a door
    per_step = simulate(batch, planner=make_planner("fsm"), compiled=False)
    assert_identical(split, per_step)
    assert split.metrics.transitions and split.metrics.collided.any()
    with pytest.raises(ValueError, match="drivers or doors"):
        simulate(batch, compiled=True)  # the whole batch compiled: still refused


_SLOT_VALUES = st.one_of(st.sampled_from([0.0, -0.0, np.nan, np.inf, -np.inf, 1.0]), st.floats(-1e3, 1e3))


@given(
    rows=st.integers(1, 6).flatmap(
        lambda slots: st.lists(st.lists(_SLOT_VALUES, min_size=slots, max_size=slots), min_size=1, max_size=4)
    )
)
@settings(max_examples=300, deadline=None)
def test_a_traced_rows_minimum_is_the_per_step_recorders_bit_for_bit(rows: list[list[float]]) -> None:
    """The compiled trace's smallest clearance and TTC over the VRU slots are NumPy's `.min(axis=1)` of the
    per-step recorder, NaN and signed zeros included (Python's `min` skips a NaN after the first slot and keeps
    the first of two equal zeros)."""
    values = np.array(rows)
    taken = np.array([compiled_run.slots_minimum(values, b) for b in range(values.shape[0])])
    np.testing.assert_array_equal(taken.view(np.int64), values.min(axis=1).view(np.int64))


_LOSSES = st.sampled_from(
    [
        {"model": "none"},
        {"model": "bernoulli", "probability": 0.5},
        {"model": "gilbert_elliott", "p_good_to_bad": 0.1, "p_bad_to_good": 0.3, "loss_bad": 0.8},
        {"model": "distance", "d50_m": 30.0, "scale_m": 5.0},
    ]
)
_GENERATIONS = st.sampled_from([{"mode": "every_step"}, {"mode": "periodic", "rate_hz": 3.3}, {"mode": "etsi_vam"}])


@st.composite
def _channels(draw) -> dict:
    """A realistic V2X channel: every loss model and generation mode, latency, jitter, RSU noise, an outage."""
    latency, jitter = draw(st.sampled_from([0.0, 0.1, 0.35])), draw(st.sampled_from([0.0, 0.07]))
    return {
        "generation": draw(_GENERATIONS),
        "latency_s": latency,
        "jitter_s": jitter,
        "loss": draw(_LOSSES),
        "track_max_age_s": latency + jitter + draw(st.sampled_from([0.2, 1.0])),
        "rsu_position_sigma_m": draw(st.sampled_from([0.0, 0.2])),
        "rsu_speed_sigma_mps": draw(st.sampled_from([0.0, 0.2])),
        "outages": draw(st.sampled_from([[], [{"start_s": 1.0, "end_s": 2.5}]])),
    }


@st.composite
def _sensors(draw) -> dict:
    """A realistic sensor: latency, misses, noise, a frame rate, a seed."""
    return {
        "sensor.latency_s": draw(st.sampled_from([0.0, 0.05, 0.2])),
        "sensor.detection_probability": draw(st.sampled_from([1.0, 0.5])),
        "sensor.position_sigma_m": draw(st.sampled_from([0.0, 0.5])),
        "sensor.velocity_sigma_mps": draw(st.sampled_from([0.0, 0.3])),
        "sensor.frame_rate_hz": draw(st.sampled_from([None, 7.0])),
        "sim.seed": draw(st.integers(0, 999)),
    }


_CATALOGUE = select(None, night=True, protocol="2026") + select(None, night=True, protocol="2023")


@settings(max_examples=8, deadline=None)
@given(
    picks=st.lists(st.integers(0, len(_CATALOGUE) - 1), min_size=1, max_size=8, unique=True),
    planner=st.sampled_from(PLANNERS),
    v2x=st.booleans(),
    sensor=st.none() | _sensors(),
    channel=st.none() | _channels(),
)
def test_random_catalogue_batches_under_random_sensors_and_channels_identical(picks, planner, v2x, sensor, channel):
    """Tests of both editions, day and night, with any sensor model and V2X channel: the automatic path (compiled,
    or split where a driver or door needs the per-step path) gives the per-step results bit for bit. (A wider
    run of this check, 6,651 variants in 523 random batches of up to 40, found no difference on 2026-11-29.)"""
    overlay = {**(sensor or {}), **({} if channel is None else {"v2x.enabled": True, "v2x.channel": channel})}
    batch = pack([build_test(_CATALOGUE[i], planner, v2x=v2x).scenario.replace(**overlay) for i in picks])
    assert_identical(simulate(batch), simulate(batch, compiled=False))
