"""The onboard sensor model: ideal path unchanged, latency, frame rate, detection probability, noise, night range,
determinism and schema errors. Expected values are analytic (constant-speed VRU, exact step arithmetic) or
statistical with stated bounds; the reference model below re-derives every report from its definition."""

from __future__ import annotations

import copy
import math
import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from vrusim import kernels
from vrusim.engine import stepper
from vrusim.engine.accumulators import FIELDS
from vrusim.engine.simulate import simulate
from vrusim.errors import UserInputError
from vrusim.metrics.summary import summary_rows
from vrusim.paper.cases import paper_scenarios
from vrusim.scenario.loading import scenario_from_mapping
from vrusim.sim.observation import SOURCE_SENSOR
from vrusim.sim.params import pack
from vrusim.sim.rng import STREAM_SENSOR_DETECT, STREAM_SENSOR_NOISE, normals, uniforms
from vrusim.sim.sensing.sensor_model import IdealSensor, RealisticSensor, make_sensor_model
from vrusim.sim.sensing.sensor_params import MAX_WHOLE_STEPS, whole_steps

DT = 0.01
SCRATCH_FIELDS = {"prev_actuator", "prev_clearance", "prev_speed"}
"""Step-to-step working state of RunMetrics, not results (see test_batch_consistency.py)."""
RESULT_ROWS = [i for i, name in enumerate(FIELDS) if name not in SCRATCH_FIELDS]


class Recorder:
    """A planner that holds its speed and records what the sensor reported each step (V2X off in its tests)."""

    mode_names = ("hold",)

    def reset(self, params) -> None:
        self.mode = np.zeros(params.size, dtype=np.int8)
        self.sensed: list[np.ndarray] = []
        self.estimate: list[np.ndarray] = []
        self.predicted: list[np.ndarray] = []
        self.age: list[np.ndarray] = []

    def act(self, observation) -> np.ndarray:
        self.sensed.append((observation.source & SOURCE_SENSOR) != 0)
        # the observation predicts a delayed report to now; undo that to record the sensor's own report
        report = observation.vru_estimate[:6].copy()
        report[0:2] -= report[2:4] * observation.vru_estimate[6]
        self.estimate.append(report)
        self.predicted.append(observation.vru_estimate[:2].copy())
        self.age.append(observation.vru_estimate[6].copy())
        return np.zeros(observation.ego_speed_mps.shape)

    def arrays(self) -> tuple[np.ndarray, np.ndarray]:
        """(sensed [N, B, K], estimate [N, 6, B, K]) over the steps run."""
        return np.stack(self.sensed), np.stack(self.estimate)


def with_sensor(base: dict, **sensor) -> dict:
    data = copy.deepcopy(base)
    data.setdefault("sensor", {}).update(sensor)
    return data


# --- ideal settings: the ideal model, bit-identical results ---------------------------------------------------


def test_default_and_night_only_settings_use_the_ideal_model(make_scenario):
    assert isinstance(make_sensor_model(pack([make_scenario()])), IdealSensor)
    night = make_scenario({"sensor": {"lighting": "night", "latency_s": 0.004}})  # 0.4 steps rounds to 0
    assert isinstance(make_sensor_model(pack([night])), IdealSensor)
    noisy = make_scenario({"sensor": {"position_sigma_m": 0.1}})
    assert isinstance(make_sensor_model(pack([night, noisy])), RealisticSensor)


def test_paper_runs_are_bit_identical_through_the_realistic_code_path(monkeypatch):
    """The six paper runs: ideal model vs the realistic model forced on with ideal settings."""
    scenarios = [scenario for _, _, scenario in paper_scenarios()]
    assert isinstance(make_sensor_model(pack(scenarios)), IdealSensor)
    ideal = simulate(scenarios)
    monkeypatch.setattr(stepper, "make_sensor_model", lambda params: RealisticSensor())
    forced = simulate(scenarios)
    assert summary_rows(forced) == summary_rows(ideal)
    assert np.array_equal(forced.metrics.values, ideal.metrics.values, equal_nan=True)
    assert forced.metrics.transitions == ideal.metrics.transitions


def test_whole_steps_rounds_to_the_nearest_step():
    assert whole_steps(0.15, 0.01) == 15  # 14.999999999999998 in floating point
    assert whole_steps(0.004, 0.01) == 0
    assert whole_steps(0.015, 0.01) == 2  # halves round up
    assert whole_steps(0.0, 0.01) == 0


# --- latency and frame rate, end to end -----------------------------------------------------------------------

CROSSING_SPEED_MPS = 1.5
CROSSING_START = (30.0, -15.0)


@pytest.fixture
def crossing(scenario_dict) -> dict:
    """Ego at 10 m/s along +x; a pedestrian crossing at a constant 1.5 m/s from t = 0 (x = 30, y = -15 + 1.5 t)."""
    scenario_dict["vrus"] = [
        {
            "type": "pedestrian",
            "start": {"x_m": CROSSING_START[0], "y_m": CROSSING_START[1]},
            "heading_deg": 90.0,
            "top_speed_mps": CROSSING_SPEED_MPS,
            "initial_speed_mps": CROSSING_SPEED_MPS,
            "trigger": {"at_time_s": 0.0},
        }
    ]
    scenario_dict["sim"]["duration_s"] = 4.0
    return scenario_dict


def run_recorded(data: dict) -> tuple[np.ndarray, np.ndarray, object]:
    recorder = Recorder()
    run = simulate([scenario_from_mapping(data)], planner=recorder)
    sensed, estimate = recorder.arrays()
    return sensed[:, 0, 0], estimate[:, :, 0, 0], run


@pytest.mark.parametrize("latency_steps", [1, 7, 25])
def test_latency_delays_detection_and_reports_the_past(crossing, latency_steps):
    ideal, _, ideal_run = run_recorded(crossing)
    sensed, estimate, run = run_recorded(with_sensor(crossing, latency_s=latency_steps * DT))
    first_visible = int(np.argmax(ideal))
    assert ideal.any() and first_visible > 0
    # first detection = first visibility + L, exactly in steps
    assert run.metrics.first_sensor_s[0] == pytest.approx((first_visible + latency_steps) * DT, abs=1e-9)
    assert ideal_run.metrics.first_sensor_s[0] == pytest.approx(first_visible * DT, abs=1e-9)
    # detected now = visible L steps ago (the hold-speed planner ignores detections: same visibility)
    assert not sensed[:latency_steps].any()
    assert np.array_equal(sensed[latency_steps:], ideal[:-latency_steps])
    # reported kinematics = the constant-speed VRU's true state L steps earlier
    steps = np.flatnonzero(sensed)
    t_measured = (steps - latency_steps) * DT
    np.testing.assert_allclose(estimate[steps, 0], CROSSING_START[0], atol=1e-9)
    np.testing.assert_allclose(estimate[steps, 1], CROSSING_START[1] + CROSSING_SPEED_MPS * t_measured, atol=1e-9)
    np.testing.assert_allclose(estimate[steps, 2], 0.0, atol=1e-9)
    np.testing.assert_allclose(estimate[steps, 3], CROSSING_SPEED_MPS, atol=1e-12)
    np.testing.assert_allclose(estimate[steps, 4:6], 0.0, atol=1e-12)
    # the planner sees the report predicted to now (exact for this constant-speed VRU), with its age L
    recorder = Recorder()
    simulate([scenario_from_mapping(with_sensor(crossing, latency_s=latency_steps * DT))], planner=recorder)
    predicted, age = np.stack(recorder.predicted)[:, :, 0, 0], np.stack(recorder.age)[:, 0, 0]
    np.testing.assert_allclose(predicted[steps, 1], CROSSING_START[1] + CROSSING_SPEED_MPS * steps * DT, atol=1e-9)
    np.testing.assert_allclose(age[steps], latency_steps * DT, atol=1e-12)


def test_frame_rate_holds_the_last_report_between_frames(crossing):
    ideal, _, _ = run_recorded(crossing)
    period, latency = 5, 3  # 20 Hz frames, 30 ms latency
    sensed, estimate, run = run_recorded(with_sensor(crossing, frame_rate_hz=20.0, latency_s=0.03))
    first_visible = int(np.argmax(ideal))
    first_frame = math.ceil(first_visible / period) * period
    assert run.metrics.first_sensor_s[0] == pytest.approx((first_frame + latency) * DT, abs=1e-9)
    for n in range(len(sensed)):
        measured = period * ((n - latency) // period)
        assert sensed[n] == (n >= latency and ideal[measured]), n
        if sensed[n]:
            assert estimate[n, 1] == pytest.approx(CROSSING_START[1] + CROSSING_SPEED_MPS * measured * DT, abs=1e-9)


# --- the model against its definition, step by step -----------------------------------------------------------


def reference(scenarios, params, visible: np.ndarray, truth: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Reports [N, B, K] and [N, 6, B, K] straight from the definition (docs/models.md, "Sensor model"), read
    from the scenarios' `sensor` fields (not from the packed `params.sensor`)."""
    steps, _, K = visible.shape
    detected = np.zeros(visible.shape, dtype=bool)
    estimate = np.zeros(truth.shape)
    for b, scenario in enumerate(scenarios):
        sensor = scenario.sensor
        latency = whole_steps(sensor.latency_s, DT)
        period = 1 if sensor.frame_rate_hz is None else max(1, whole_steps(1 / sensor.frame_rate_hz, DT))
        seed = params.seed[b : b + 1]
        sigma = [sensor.position_sigma_m] * 2 + [sensor.velocity_sigma_mps] * 2
        for n in range(steps):
            if n < latency:
                estimate[n, :, b] = truth[0, :, b]
                continue
            m = period * ((n - latency) // period)
            draw = uniforms(seed, m, STREAM_SENSOR_DETECT, K)[0]
            noise = normals(seed, m, STREAM_SENSOR_NOISE, 4 * K)[0].reshape(K, 4).T
            detected[n, b] = visible[m, b] & (draw < sensor.detection_probability)
            estimate[n, :, b] = truth[m, :, b]
            for axis in range(4):
                if sigma[axis] > 0:
                    estimate[n, axis, b] += sigma[axis] * noise[axis]
    return detected, estimate


def drive(params, visible: np.ndarray, truth: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    model = RealisticSensor()
    model.reset(params)
    out = [model.observe(n, n * DT, visible[n], truth[n]) for n in range(visible.shape[0])]
    return np.stack([d for d, _ in out]), np.stack([e for _, e in out])


def sensor_scenarios(make_scenario, settings_list: list[dict], vrus: int = 1) -> list:
    """One minimal scenario per sensor setting (seed included), with `vrus` VRU slots."""
    far = make_scenario().model_dump(mode="json")["vrus"][0]
    scenarios = []
    for index, sensor in enumerate(settings_list):
        sensor = dict(sensor)
        seed = sensor.pop("seed", index)
        scenarios.append(make_scenario({"sensor": sensor, "sim": {"seed": seed}, "vrus": [far] * vrus}))
    return scenarios


def sensor_batch(make_scenario, settings_list: list[dict], vrus: int = 1):
    """Packed batch of `sensor_scenarios`."""
    return pack(sensor_scenarios(make_scenario, settings_list, vrus))


sensor_settings = st.fixed_dictionaries(
    {
        "latency_s": st.integers(0, 12).map(lambda n: n * DT),
        "frame_rate_hz": st.none() | st.sampled_from([100.0, 50.0, 25.0, 20.0, 12.5]),
        "detection_probability": st.sampled_from([1.0, 0.9, 0.5, 0.05]),
        "position_sigma_m": st.sampled_from([0.0, 0.3]),
        "velocity_sigma_mps": st.sampled_from([0.0, 0.2]),
        "seed": st.integers(0, 2**62),
    }
)


@settings(deadline=None, max_examples=40)
@given(st.lists(sensor_settings, min_size=1, max_size=5), st.integers(1, 3), st.integers(0, 2**32 - 1))
def test_reports_match_the_definition(make_scenario, settings_list, vrus, data_seed):
    scenarios = sensor_scenarios(make_scenario, settings_list, vrus)
    params = pack(scenarios)
    rng = np.random.default_rng(data_seed)
    steps, shape = 40, params.vru_valid.shape
    visible = rng.random((steps, *shape)) < 0.6
    truth = rng.normal(size=(steps, 6, *shape))
    detected, estimate = drive(params, visible, truth)
    want_detected, want_estimate = reference(scenarios, params, visible, truth)
    assert np.array_equal(detected, want_detected)
    np.testing.assert_allclose(estimate, want_estimate, rtol=0, atol=1e-12)


def test_returned_arrays_are_fresh(make_scenario):
    """The caller may keep or change a report: the held report inside the model is not shared with it."""
    params = sensor_batch(make_scenario, [{"latency_s": 0.02, "frame_rate_hz": 50.0}])  # L = 2, F = 2 steps
    model = RealisticSensor()
    model.reset(params)
    visible, truth = np.ones((1, 1), dtype=bool), np.ones((6, 1, 1))
    reports = [model.observe(n, n * DT, visible, truth * (n + 1)) for n in range(3)]
    assert [bool(d[0, 0]) for d, _ in reports] == [False, False, True]
    reports[2][0][:] = False
    reports[2][1][:] = -1.0
    detected, estimate = model.observe(3, 3 * DT, visible, truth * 4)  # holds the frame measured at step 0
    assert detected[0, 0]
    assert np.array_equal(estimate, np.ones((6, 1, 1)))


# --- statistics ------------------------------------------------------------------------------------------------


def test_detection_probability_is_binomial(make_scenario):
    """400 variants x 250 steps, visible about half the time: detected only when visible, at rate p."""
    p = 0.3
    params = sensor_batch(make_scenario, [{"detection_probability": p}] * 400)
    steps, shape = 250, params.vru_valid.shape
    visible = np.random.default_rng(1).random((steps, *shape)) < 0.5
    detected, _ = drive(params, visible, np.zeros((steps, 6, *shape)))
    assert not (detected & ~visible).any()
    n = visible.sum()
    rate = detected[visible].mean()
    assert abs(rate - p) < 5 * math.sqrt(p * (1 - p) / n)  # 5 sigma: a wrong p or a biased draw fails
    # independent frames: P(detected at n and n + 1 | visible at both) = p^2
    both = visible[1:] & visible[:-1]
    pairs = (detected[1:] & detected[:-1])[both].mean()
    assert abs(pairs - p * p) < 5 * math.sqrt(p * p * (1 - p * p) / both.sum())


def test_first_detection_delay_is_geometric(make_scenario):
    """End to end: a VRU in view from t = 0 is first detected after a Geometric(p) number of missed frames."""
    p = 0.4
    still = {"type": "pedestrian", "start": [12.0, 0.0], "heading_deg": 90.0, "top_speed_mps": 0.0}
    scenarios = [
        make_scenario(
            {
                "ego": {"cruise_speed_mps": 0.0},
                "vrus": [still],
                "sensor": {"detection_probability": p},
                "sim": {"seed": seed, "duration_s": 0.5},
            }
        )
        for seed in range(2000)
    ]
    misses = simulate(scenarios).metrics.first_sensor_s / DT
    assert np.isfinite(misses).all()  # (1 - p)^50: never missed for 50 frames
    assert np.allclose(misses, np.round(misses))
    mean, sd = (1 - p) / p, math.sqrt(1 - p) / p
    assert abs(misses.mean() - mean) < 5 * sd / math.sqrt(len(misses))
    assert abs(np.mean(misses == 0) - p) < 5 * math.sqrt(p * (1 - p) / len(misses))


def test_noise_is_zero_mean_with_the_given_sigma(make_scenario):
    position_sigma, velocity_sigma = 0.4, 0.15
    params = sensor_batch(
        make_scenario, [{"position_sigma_m": position_sigma, "velocity_sigma_mps": velocity_sigma}] * 400
    )
    steps, shape = 250, params.vru_valid.shape
    truth = np.broadcast_to(np.array([3.0, -2.0, 1.0, 0.5, 0.25, -0.125])[None, :, None, None], (steps, 6, *shape))
    _, estimate = drive(params, np.ones((steps, *shape), dtype=bool), np.ascontiguousarray(truth))
    error = (estimate - truth).transpose(1, 0, 2, 3).reshape(6, -1)
    n = error.shape[1]
    for axis, sigma in enumerate([position_sigma, position_sigma, velocity_sigma, velocity_sigma]):
        assert abs(error[axis].mean()) < 5 * sigma / math.sqrt(n), axis
        assert abs(error[axis].std() / sigma - 1) < 5 / math.sqrt(2 * n), axis
    assert np.array_equal(error[4:], np.zeros((2, n)))  # accelerations: passed on without noise
    correlation = np.corrcoef(error[:4])
    assert np.all(np.abs(correlation[np.triu_indices(4, 1)]) < 5 / math.sqrt(n))  # independent axes
    x = error[0].reshape(steps, -1)
    assert abs(np.corrcoef(x[1:].ravel(), x[:-1].ravel())[0, 1]) < 5 / math.sqrt(n)  # independent frames


# --- night ------------------------------------------------------------------------------------------------------


def seen_at_start(make_scenario, distance_fraction: float, factor: float, lighting: str, range_m=20.0) -> bool:
    """Whether a standing pedestrian (r = 0.5 m) at distance_fraction x range ahead of the apex is seen at t = 0."""
    apex_x = 4.5 / 2  # the minimal ego is centred on the origin, facing +x
    vru = {"type": "pedestrian", "start": [apex_x + distance_fraction * range_m, 0.0], "heading_deg": 90.0}
    scenario = make_scenario(
        {
            "ego": {"cruise_speed_mps": 0.0},
            "vrus": [{**vru, "top_speed_mps": 0.0, "radius_m": 0.5}],
            "sensor": {"range_m": range_m, "lighting": lighting, "night_range_factor": factor},
            "sim": {"duration_s": DT},
        }
    )
    return simulate([scenario]).metrics.first_sensor_s[0] == 0.0


def test_night_halves_the_range(make_scenario):
    assert seen_at_start(make_scenario, 0.7, 0.5, "day")
    assert not seen_at_start(make_scenario, 0.7, 0.5, "night")
    assert seen_at_start(make_scenario, 0.4, 0.5, "day")
    assert seen_at_start(make_scenario, 0.4, 0.5, "night")
    assert seen_at_start(make_scenario, 0.7, 0.1, "day")  # the factor only applies at night
    day, night = (make_scenario({"sensor": {"lighting": lit}}) for lit in ("day", "night"))
    assert pack([day, night]).sensor_range_m.tolist() == [20.0, 10.0]


@settings(deadline=None, max_examples=30)
@given(st.floats(0.05, 1.0), st.floats(0.05, 1.2), st.floats(5.0, 60.0))
def test_night_visibility_uses_the_reduced_range(make_scenario, factor, fraction, range_m):
    edge = fraction * range_m - 0.5 - factor * range_m  # footprint's near edge beyond the night range
    if abs(edge) < 1e-6 or fraction * range_m <= 0.5:
        return
    assert seen_at_start(make_scenario, fraction, factor, "night", range_m) == (edge < 0)


# --- determinism ------------------------------------------------------------------------------------------------


def realistic_variants(paper: dict, count: int) -> list:
    """Paper pedestrian variants with mixed sensor settings (some ideal), closed loop with the FSM."""
    rng = np.random.default_rng(4)
    out = []
    for i in range(count):
        data = copy.deepcopy(paper)
        data["name"] = f"variant-{i}"
        data["sim"].update(duration_s=8.0, seed=int(rng.integers(0, 2**62)))
        data["ego"]["cruise_speed_mps"] = round(float(rng.uniform(10.0, 18.0)), 3)
        data["v2x"]["enabled"] = bool(rng.random() < 0.3)
        if i % 5:  # every fifth variant keeps the ideal sensor
            data["sensor"].update(
                latency_s=float(rng.choice([0.0, 0.05, 0.1, 0.3])),
                detection_probability=float(rng.choice([1.0, 0.9, 0.5])),
                position_sigma_m=float(rng.choice([0.0, 0.2])),
                velocity_sigma_mps=float(rng.choice([0.0, 0.3])),
                frame_rate_hz=[None, 10.0, 20.0][int(rng.integers(3))],
                lighting=str(rng.choice(["day", "night"])),
            )
        out.append(scenario_from_mapping(data))
    return out


@pytest.fixture(scope="module")
def variants(paper_pedestrian_dict):
    return realistic_variants(paper_pedestrian_dict, 1000)


def results(run, b: int) -> tuple[np.ndarray, list]:
    transitions = [(t, old, new) for t, index, old, new in run.metrics.transitions if index == b]
    return run.metrics.values[RESULT_ROWS, b], transitions


def test_variant_alone_equals_variant_in_a_batch_of_1000(variants):
    big = simulate(variants)
    assert len({s.sim.seed for s in variants}) == len(variants)
    assert 0 < big.metrics.collided.sum() < len(variants)  # the settings matter to the outcome
    for b in [0, 1, 2, 3, 7, 123, 499, 998]:
        alone = simulate([variants[b]])
        solo_values, solo_transitions = results(alone, 0)
        batch_values, batch_transitions = results(big, b)
        assert np.array_equal(solo_values, batch_values, equal_nan=True), b
        assert solo_transitions == batch_transitions, b


def test_parallel_kernels_match_serial(monkeypatch, variants):
    subset = variants[:64]
    serial = simulate(subset)
    monkeypatch.setattr(kernels, "PARALLEL_MIN_BATCH", 1)
    parallel = simulate(subset)
    assert np.array_equal(serial.metrics.values, parallel.metrics.values, equal_nan=True)
    assert serial.metrics.transitions == parallel.metrics.transitions


def test_same_seed_same_reports_other_seed_other_reports(crossing):
    noisy = with_sensor(crossing, detection_probability=0.7, position_sigma_m=0.2, velocity_sigma_mps=0.1)
    first = run_recorded(noisy)
    again = run_recorded(noisy)
    noisy["sim"]["seed"] = 1
    other = run_recorded(noisy)
    assert np.array_equal(first[0], again[0]) and np.array_equal(first[1], again[1])
    assert not np.array_equal(first[0], other[0])
    assert not np.array_equal(first[1], other[1])


# --- schema ----------------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("field", "value", "reason"),
    [
        ("latency_s", -0.1, r"greater than or equal to 0"),
        ("latency_s", 11.0, r"less than or equal to 10"),
        ("detection_probability", 0.0, r"greater than 0"),
        ("detection_probability", 1.5, r"less than or equal to 1"),
        ("position_sigma_m", -0.2, r"greater than or equal to 0"),
        ("velocity_sigma_mps", -0.2, r"greater than or equal to 0"),
        ("frame_rate_hz", 0.0, r"greater than 0"),
        ("lighting", "dusk", r"'day' or 'night'"),
        ("night_range_factor", 0.0, r"greater than 0"),
        ("night_range_factor", 1.2, r"less than or equal to 1"),
        ("night_range_factor", math.nan, r"finite number"),
    ],
)
def test_bad_sensor_field_is_named(scenario_dict, field, value, reason):
    scenario_dict["sensor"] = {field: value}
    with pytest.raises(UserInputError) as info:
        scenario_from_mapping(scenario_dict, "case.yaml")
    lines = str(info.value).splitlines()
    assert lines[0] == "case.yaml: invalid scenario"
    assert len(lines) == 2
    path, _, message = lines[1].strip().partition(": ")
    assert path == f"sensor.{field}"
    assert re.search(reason, message), message


def test_fused_sensor_estimates_carry_their_age(make_scenario):
    """A 0.1 s latency at 20 Hz: the observation's age of a sensor estimate is latency + time held, in
    [0.1, 0.15) s, and the ideal sensor's is 0."""
    from vrusim.sim.params import pack
    from vrusim.sim.sensing.sensor_model import RealisticSensor

    scenario = make_scenario({"sensor": {"latency_s": 0.1, "frame_rate_hz": 20.0}})
    sensor = RealisticSensor()
    sensor.reset(pack([scenario]))
    ages = np.array([sensor.age_s(step, 0.01)[0] for step in range(10, 60)])
    assert ages.min() == pytest.approx(0.1) and ages.max() == pytest.approx(0.14)
    assert np.all(np.diff(ages)[np.diff(ages) < 0] == pytest.approx(-0.04))  # a new frame every 5 steps


# --- delays longer than the run --------------------------------------------------------------------------------


def test_whole_steps_saturates_instead_of_wrapping_around():
    with np.errstate(all="raise"):
        assert whole_steps(10.0, 1e-200) == MAX_WHOLE_STEPS  # 1e201 steps
        assert whole_steps(1.0 / 1e-17, DT) == MAX_WHOLE_STEPS  # a frame every 1e19 steps: beyond int64
        assert whole_steps(np.array([1e300, 0.15]), 1e-10).tolist() == [MAX_WHOLE_STEPS, 1_500_000_000]


@pytest.mark.parametrize("compiled", [True, False])
def test_a_latency_beyond_the_run_keeps_a_buffer_of_the_run_and_reports_nothing(crossing, compiled):
    """A 10 s latency in a 0.5 s run (50 steps) reports nothing, exactly as a latency of the whole run does, and
    the ring buffer holds the run's steps + 1 (a 1,001-step buffer before; at dt = 1e-8 s it asked 44 GiB)."""
    crossing["sim"]["duration_s"] = 0.5
    runs = {
        latency: simulate([scenario_from_mapping(with_sensor(crossing, latency_s=latency))], compiled=compiled)
        for latency in (10.0, 0.5)
    }
    assert np.array_equal(runs[10.0].metrics.values, runs[0.5].metrics.values, equal_nan=True)
    assert np.isnan(runs[10.0].metrics.first_sensor_s[0])
    sensor = RealisticSensor()
    sensor.reset(pack([scenario_from_mapping(with_sensor(crossing, latency_s=10.0))]))
    assert sensor.history.shape[0] == sensor.seen.shape[0] == 51


def test_a_frame_rate_too_low_to_give_a_second_frame_is_never_an_every_step_sensor(crossing):
    """1e-17 Hz at dt = 0.01 s is a frame every 1e19 steps, beyond int64: it wrapped to an every-step sensor."""
    slow, slower = (run_recorded(with_sensor(crossing, frame_rate_hz=rate))[0] for rate in (1e-6, 1e-17))
    ideal = run_recorded(crossing)[0]
    assert ideal.any() and not slow.any()  # the only frame, at step 0, sees nothing yet
    assert np.array_equal(slow, slower)


def test_sensor_and_v2x_buffers_beyond_their_budget_are_refused(crossing, monkeypatch):
    """The budget reads the buffers as allocated: 10 s of latency at dt = 1e-4 s is 100,000 rows x 49 bytes."""
    crossing["sim"].update(dt_s=1e-4, duration_s=20.0)
    scenario = scenario_from_mapping(with_sensor(crossing, latency_s=10.0))
    monkeypatch.setenv("VRUSIM_LIMIT_DELAY_BUFFER_BYTES", "4000000")
    with pytest.raises(UserInputError, match=r"sensor\.latency_s .* over sim\.dt_s: 1 variants x 1 VRUs .*limit"):
        simulate([scenario])
    crossing["sim"]["duration_s"] = 0.5  # the run is what bounds the buffer: 5,001 rows
    simulate([scenario_from_mapping(with_sensor(crossing, latency_s=10.0))])
