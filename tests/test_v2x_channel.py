"""The realistic V2X channel: generation rules, delay, loss models, outages, RSU noise, tracks, determinism.

Channel-level tests drive `RealisticChannel.deliver` directly with synthetic RSU output (what the RSU covers,
the true VRU kinematics, the ego's distance to the RSU) and compare with analytic expectations; engine-level
tests run whole scenarios.
"""

from __future__ import annotations

import copy
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import PAPER_FILES, minimal_scenario_dict
from test_batch_consistency import SCRATCH_FIELDS, metric_arrays
from vrusim import kernels
from vrusim.engine.simulate import simulate
from vrusim.errors import UserInputError
from vrusim.scenario.loading import load_scenario, scenario_from_mapping
from vrusim.scenario.v2x import V2X_PROFILES, ChannelSpec, GilbertElliottLoss, load_profiles
from vrusim.sim.params import BatchParams, pack
from vrusim.sim.rng import STREAM_V2X_JITTER, uniforms
from vrusim.sim.v2x.channel import RealisticChannel, make_channel
from vrusim.sim.v2x.messages import IdealChannel, V2xMessages

DT = 0.01


# ---------------------------------------------------------------- helpers


def channel_batch(channel, seeds, vrus: int = 1) -> BatchParams:
    """A batch of minimal scenarios with V2X on and `channel`, one variant per seed, `vrus` VRU slots."""
    data = minimal_scenario_dict()
    data["v2x"] = {"enabled": True, "rsu": [0.0, 0.0], "channel": channel}
    data["vrus"] = [copy.deepcopy(data["vrus"][0]) for _ in range(vrus)]
    base = scenario_from_mapping(data, "test")
    return pack([base.model_copy(update={"sim": base.sim.model_copy(update={"seed": int(s)})}) for s in seeds])


@dataclass
class Record:
    """What the channel output at each step: [T, B, K] arrays, and the channel itself."""

    received: np.ndarray
    age_s: np.ndarray
    message_step: np.ndarray
    x_m: np.ndarray
    channel: RealisticChannel


def constant_velocity(vx: float, vy: float = 0.0, x0: float = 0.0, y0: float = 0.0) -> Callable:
    def kinematics(n: int, shape) -> np.ndarray:
        out = np.zeros((6, *shape))
        out[0], out[1], out[2], out[3] = x0 + vx * n * DT, y0 + vy * n * DT, vx, vy
        return out

    return kinematics


def drive(params: BatchParams, steps: int, kinematics=None, covered=None, in_range=None, link_m=None) -> Record:
    """Run the channel over `steps` steps; `covered` / `in_range` (n → bool or [B, K]) default to always."""
    kinematics = kinematics or constant_velocity(0.0)
    shape = params.vru_valid.shape
    channel = RealisticChannel()
    channel.reset(params)
    rows: dict[str, list] = {"received": [], "age_s": [], "message_step": [], "x_m": []}
    for n in range(steps):
        cov = np.broadcast_to(True if covered is None else covered(n), shape).copy()
        rng = np.broadcast_to(True if in_range is None else in_range(n), shape) & cov
        link = np.zeros(shape[0]) if link_m is None else np.asarray(link_m, dtype=float)
        out = channel.deliver(n * DT, V2xMessages(rng, kinematics(n, shape), np.zeros(shape), cov, link))
        rows["received"].append(out.received)
        rows["age_s"].append(out.age_s)
        rows["message_step"].append(channel.message_step.copy())
        rows["x_m"].append(out.kinematics[0])
    return Record(*(np.stack(rows[name]) for name in rows), channel)


def deliveries(record: Record, b: int = 0, k: int = 0) -> list[tuple[int, int]]:
    """(delivery step, generation step) of every message the ego's track took over."""
    steps = record.message_step[:, b, k]
    out, previous = [], -1
    for n, g in enumerate(steps):
        if g >= 0 and g != previous:
            out.append((n, int(g)))
        previous = g if g >= 0 else previous
    return out


def lost_sequence(record: Record, period_steps: int) -> np.ndarray:
    """[B, M] True where the m-th periodic message (zero latency) was lost."""
    generated = np.arange(0, record.message_step.shape[0], period_steps)
    return generated[None, :] != record.message_step[generated, :, 0].T


def runs_of_true(row: np.ndarray) -> list[int]:
    """Lengths of the runs of True that neither start at the first nor end at the last element."""
    lengths, run = [], 0
    for i, value in enumerate(row):
        if value:
            run += 1
        elif run:
            if i - run > 0:
                lengths.append(run)
            run = 0
    return lengths


# ---------------------------------------------------------------- profiles and factory


def test_profiles_are_valid_and_only_ideal_is_ideal():
    assert {"ideal", "typical", "lossy", "bursty", "congested", "etsi"} <= set(V2X_PROFILES)
    assert [name for name, spec in V2X_PROFILES.items() if spec.is_ideal] == ["ideal"]
    for spec in V2X_PROFILES.values():
        assert ChannelSpec.model_validate(spec.model_dump(mode="json")) == spec
    typical = V2X_PROFILES["typical"]
    assert (typical.generation.mode, typical.generation.rate_hz, typical.latency_s, typical.jitter_s) == (
        "periodic",
        10.0,
        0.1,
        0.02,
    )
    assert typical.loss.probability == 0.05
    assert V2X_PROFILES["lossy"].loss.probability == 0.3


def test_make_channel_keeps_the_ideal_code_path(make_scenario):
    paper = [load_scenario(f).with_v2x(v) for f in PAPER_FILES for v in (False, True)]
    assert isinstance(make_channel(pack(paper)), IdealChannel)
    off = make_scenario({"v2x": {"enabled": False, "channel": "lossy"}})
    assert isinstance(make_channel(pack([off])), IdealChannel)
    on = make_scenario({"v2x": {"enabled": True, "rsu": [0, 0], "channel": "lossy"}})
    assert isinstance(make_channel(pack([paper[0], on])), RealisticChannel)


@pytest.fixture(scope="module")
def paper_runs():
    return [load_scenario(f).with_v2x(v) for f in PAPER_FILES for v in (False, True)]


def test_realistic_channel_with_the_ideal_profile_is_bit_identical(paper_runs):
    """The kernel path with ideal settings reproduces IdealChannel bit for bit on the paper's six runs."""
    ideal = simulate(paper_runs, channel=IdealChannel(), trace=True)
    realistic = simulate(paper_runs, channel=RealisticChannel(), trace=True)
    a, b = metric_arrays(ideal.metrics), metric_arrays(realistic.metrics)
    for name in a:
        assert np.array_equal(a[name], b[name], equal_nan=True), name
    assert ideal.metrics.transitions == realistic.metrics.transitions
    for name in ideal.trace:
        assert np.array_equal(ideal.trace[name], realistic.trace[name], equal_nan=True), name


# ---------------------------------------------------------------- generation and delay


def test_periodic_messages_and_constant_velocity_prediction():
    """10 Hz, no delay, no loss: a message every 0.1 s; between them the track is x_g + v_g (t - t_g)."""
    params = channel_batch({"generation": {"mode": "periodic", "rate_hz": 10}}, [0])
    accel = 0.8

    def accelerating(n, shape):  # x = a t^2 / 2: the prediction (constant velocity) differs from the truth
        out = np.zeros((6, *shape))
        t = n * DT
        out[0], out[2], out[4] = 0.5 * accel * t * t, accel * t, accel
        return out

    record = drive(params, 300, accelerating)
    assert deliveries(record) == [(n, n) for n in range(0, 300, 10)]
    assert record.received.all()
    for n in range(300):
        g = n - n % 10
        t, t_g = n * DT, g * DT
        assert record.age_s[n, 0, 0] == pytest.approx(t - t_g, abs=1e-12)
        expected = 0.5 * accel * t_g * t_g + accel * t_g * (t - t_g)
        assert record.x_m[n, 0, 0] == pytest.approx(expected, abs=1e-12)


def test_periodic_schedule_restarts_after_a_missed_slot():
    """A coverage gap over the 0.30 s slot restarts the schedule at re-entry; a gap between slots does not."""
    params = channel_batch({"generation": {"mode": "periodic", "rate_hz": 10}, "track_max_age_s": 0.0}, [0])
    missed = drive(params, 70, covered=lambda n: not 25 <= n < 35)
    assert [g for _, g in deliveries(missed)] == [0, 10, 20, 35, 45, 55, 65]
    between = drive(params, 70, covered=lambda n: not 12 <= n < 18)
    assert [g for _, g in deliveries(between)] == [0, 10, 20, 30, 40, 50, 60]


def test_periodic_rate_not_a_multiple_of_the_step():
    """3 Hz at dt = 0.01 s: slots at j/3 s fall on steps ceil(100 j / 3), i.e. the mean rate is exact."""
    params = channel_batch({"generation": {"mode": "periodic", "rate_hz": 3}}, [0])
    steps = [g for _, g in deliveries(drive(params, 1000))]
    assert steps == [math.ceil(100 * j / 3 - 1e-6) for j in range(len(steps))]
    assert len(steps) == 30


@pytest.mark.parametrize("latency_s", [0.05, 0.25, 0.3])
def test_fixed_latency_delays_the_first_delivery(latency_s):
    """First delivery = first coverage + L (to the step); the age right after each delivery is L."""
    first_covered = 37
    params = channel_batch({"generation": {"mode": "periodic", "rate_hz": 10}, "latency_s": latency_s}, [0])
    record = drive(params, 200, covered=lambda n: n >= first_covered)
    lag = round(latency_s / DT)
    got = deliveries(record)
    assert got[0] == (first_covered + lag, first_covered)
    assert not record.received[: first_covered + lag].any()
    for n, g in got:
        assert n - g == lag
        assert record.age_s[n, 0, 0] == pytest.approx(latency_s, abs=1e-12)


def test_latency_in_a_scenario_delays_the_first_v2x_message(paper_pedestrian):
    """Paper pedestrian, V2X on: the ideal first message is at 2.10 s; 0.3 s of latency moves it to 2.40 s."""
    paper_pedestrian["v2x"]["enabled"] = True
    ideal = simulate([scenario_from_mapping(paper_pedestrian)]).metrics.first_v2x_s[0]
    paper_pedestrian["v2x"]["channel"] = {"generation": {"mode": "every_step"}, "latency_s": 0.3}
    delayed = simulate([scenario_from_mapping(paper_pedestrian)]).metrics.first_v2x_s[0]
    assert ideal == pytest.approx(2.10, abs=1e-9)
    assert delayed == pytest.approx(ideal + 0.3, abs=DT + 1e-9)


def test_jitter_delay_distribution():
    """Delay L + U(0, J) rounded up to steps: with L = 10 dt, J = 5 dt the age on delivery is (10 + j) dt,
    j = 1..5 equally likely (10^5 messages; each frequency within 4.5 binomial standard deviations)."""
    seeds = np.arange(1000)
    params = channel_batch({"generation": {"rate_hz": 10}, "latency_s": 0.1, "jitter_s": 0.05}, seeds)
    record = drive(params, 1000)
    lags = np.array([n - g for b in range(len(seeds)) for n, g in deliveries(record, b)])
    assert len(lags) >= 99_000
    assert lags.min() >= 11 and lags.max() <= 15
    frequencies = np.bincount(lags - 11, minlength=5) / len(lags)
    assert np.all(np.abs(frequencies - 0.2) < 4.5 * math.sqrt(0.2 * 0.8 / len(lags)))
    assert abs(lags.mean() * DT - 0.13) < 4.5 * math.sqrt(2.0) * DT / math.sqrt(len(lags))


def test_jitter_reorders_and_older_messages_are_ignored():
    """Every step with 0.05 s of jitter: messages overtake each other; the track never goes back in time."""
    params = channel_batch({"generation": {"mode": "every_step"}, "jitter_s": 0.05}, range(20))
    record = drive(params, 400)
    for b in range(20):
        steps = record.message_step[:, b, 0]
        assert np.all(np.diff(steps) >= 0)
        lags = [n - g for n, g in deliveries(record, b)]
        assert min(lags) >= 0 and max(lags) <= 5
    channel = record.channel
    assert np.all(channel.delivered < channel.generated)  # some were overtaken


@pytest.mark.parametrize("jitter_s", [0.0, 0.05])
def test_each_step_takes_the_newest_message_due(jitter_s):
    """Every step's track is the newest message due by then that is newer than the track: a queue model built
    from the same delay draws. With jitter a message can be due behind one that is not, which a scan that stops
    at the first message not yet due would miss."""
    seeds = np.arange(20)
    params = channel_batch({"generation": {"mode": "every_step"}, "latency_s": 0.02, "jitter_s": jitter_s}, seeds)
    steps = 300
    record = drive(params, steps)
    jitter = np.stack([uniforms(seeds, g, STREAM_V2X_JITTER, 1)[:, 0] for g in range(steps)], axis=1)
    due = np.arange(steps) + np.ceil((0.02 + jitter_s * jitter) / DT - 1e-9).astype(int)
    for b in seeds:
        track, expected = -1, []
        for n in range(steps):
            newer_due = [g for g in range(track + 1, n + 1) if due[b, g] <= n]
            track = max(newer_due, default=track)
            expected.append(track)
        assert record.message_step[:, b, 0].tolist() == expected


# ---------------------------------------------------------------- loss models


def test_bernoulli_loss_rate():
    """10^5 messages at 30 % loss: the delivered fraction within 4.5 binomial standard deviations."""
    params = channel_batch({"loss": {"model": "bernoulli", "probability": 0.3}}, np.arange(1000))
    record = drive(params, 1000)
    channel = record.channel
    total = channel.generated.sum()
    assert total == 100_000
    fraction = channel.delivered.sum() / total
    assert abs(fraction - 0.7) < 4.5 * math.sqrt(0.3 * 0.7 / total)
    lost = lost_sequence(record, 10)
    assert lost.sum() == total - channel.delivered.sum()
    # independence: a loss says nothing about the next message
    after_loss = lost[:, 1:][lost[:, :-1]].mean()
    assert abs(after_loss - 0.3) < 4.5 * math.sqrt(0.21 / lost[:, :-1].sum())


def test_gilbert_burst_lengths_and_stationary_loss():
    """Gilbert (loss 0 good, 1 bad): stationary loss p_gb / (p_gb + p_bg), loss bursts geometric with mean
    1 / p_bg (10^5 messages)."""
    loss = {"model": "gilbert_elliott", "p_good_to_bad": 0.05, "p_bad_to_good": 0.25}
    params = channel_batch({"loss": loss}, np.arange(1000))
    record = drive(params, 1000)
    lost = lost_sequence(record, 10)
    model = GilbertElliottLoss.model_validate(loss)
    # loss fraction of a two-state chain: variance inflated by (1 + lambda) / (1 - lambda), lambda = 1 - p_gb - p_bg
    lam = 1 - 0.05 - 0.25
    sigma = math.sqrt(model.stationary_bad * (1 - model.stationary_bad) * (1 + lam) / (1 - lam) / lost.size)
    assert abs(lost.mean() - model.stationary_loss) < 4.5 * sigma
    bursts = np.array([length for row in lost for length in runs_of_true(row)])
    assert len(bursts) > 3000
    assert abs(bursts.mean() - model.mean_bad_run_messages) < 4.5 * math.sqrt(0.75) / 0.25 / math.sqrt(len(bursts))
    for length in (1, 2, 3, 4):
        p = 0.25 * 0.75 ** (length - 1)
        assert abs(np.mean(bursts == length) - p) < 4.5 * math.sqrt(p * (1 - p) / len(bursts))


def test_elliott_stationary_loss():
    """Elliott (some loss in both states): the loss rate is (1 - pi_B) loss_good + pi_B loss_bad."""
    loss = {"model": "gilbert_elliott", "p_good_to_bad": 0.1, "p_bad_to_good": 0.3, "loss_good": 0.05, "loss_bad": 0.7}
    params = channel_batch({"loss": loss}, np.arange(1000))
    channel = drive(params, 1000).channel
    model = GilbertElliottLoss.model_validate(loss)
    assert model.stationary_loss == pytest.approx(0.75 * 0.05 + 0.25 * 0.7)
    lost = 1 - channel.delivered.sum() / channel.generated.sum()
    assert abs(lost - model.stationary_loss) < 0.01  # about 4.5 standard deviations of the correlated estimate


@pytest.mark.parametrize("distance_m", [20.0, 50.0, 65.0, 90.0])
def test_distance_delivery_ratio(distance_m):
    """Delivered fraction at a fixed RSU–ego distance = 1 / (1 + exp((d - d50) / scale))."""
    params = channel_batch({"loss": {"model": "distance", "d50_m": 50.0, "scale_m": 10.0}}, np.arange(500))
    channel = drive(params, 1000, link_m=np.full(500, distance_m)).channel
    pdr = 1 / (1 + math.exp((distance_m - 50.0) / 10.0))
    total = channel.generated.sum()
    assert abs(channel.delivered.sum() / total - pdr) < 4.5 * math.sqrt(pdr * (1 - pdr) / total) + 1e-9


def test_out_of_range_messages_are_not_delivered():
    params = channel_batch({"generation": {"mode": "every_step"}, "track_max_age_s": 0.0}, [0])
    record = drive(params, 100, in_range=lambda n: 20 <= n < 60)
    assert np.array_equal(record.received[:, 0, 0], (np.arange(100) >= 20) & (np.arange(100) < 60))


# ---------------------------------------------------------------- outages and track age


def test_outages_deliver_nothing_and_tracks_expire():
    outages = [{"start_s": 1.0, "end_s": 2.0}, {"start_s": 3.0, "end_s": 3.5}]
    spec = {"generation": {"rate_hz": 10}, "latency_s": 0.1, "outages": outages, "track_max_age_s": 0.3}
    params = channel_batch(spec, [0])
    record = drive(params, 500)
    for n, g in deliveries(record):
        for window in outages:
            assert not window["start_s"] <= n * DT < window["end_s"], f"delivered at {n * DT:.2f} s"
            assert not window["start_s"] <= g * DT < window["end_s"], f"sent at {g * DT:.2f} s"
    received = record.received[:, 0, 0]
    # last delivery before the first outage: sent 0.80 s, arrives 0.90 s; dropped when older than 0.3 s
    assert received[110] and not received[111:210].any()
    assert received[210] and record.age_s[210, 0, 0] == pytest.approx(0.1)  # sent 2.00 s
    assert received[310] and not received[311:360].any() and received[360]


def test_track_dropped_after_max_age():
    """Coverage ends at 0.5 s: the last message (0.40 s) is kept until it is older than 0.35 s."""
    params = channel_batch({"generation": {"rate_hz": 10}, "track_max_age_s": 0.35}, [0])
    record = drive(params, 120, constant_velocity(1.5), covered=lambda n: n < 50)
    received = record.received[:, 0, 0]
    assert received[:76].all() and not received[76:].any()
    assert record.age_s[75, 0, 0] == pytest.approx(0.35)
    assert record.x_m[75, 0, 0] == pytest.approx(1.5 * 0.75)  # constant velocity: exact prediction


# ---------------------------------------------------------------- ETSI VAM rule


def etsi_steps(kinematics, steps: int = 1200, covered=None, **generation) -> list[int]:
    params = channel_batch({"generation": {"mode": "etsi_vam", **generation}}, [0])
    return [g for _, g in deliveries(drive(params, steps, kinematics, covered))]


def test_etsi_position_rule_at_walking_speed():
    """1.8 m/s: 4 m take 2.22 s, i.e. a message every ceil(4 / (1.8 dt)) = 223 steps."""
    interval = math.ceil(4.0 / (1.8 * DT))
    assert interval == 223
    assert etsi_steps(constant_velocity(1.8)) == list(range(0, 1200, interval))


def test_etsi_at_least_every_five_seconds():
    """0.5 m/s (4 m would take 8 s) and standing still: a message every 5 s."""
    assert etsi_steps(constant_velocity(0.5), 1600) == [0, 500, 1000, 1500]
    assert etsi_steps(constant_velocity(0.0), 1600) == [0, 500, 1000, 1500]


def test_etsi_never_more_often_than_every_tenth_of_a_second():
    """60 m/s (4 m in 0.067 s): limited to one message per 0.1 s."""
    assert etsi_steps(constant_velocity(60.0), 100) == list(range(0, 100, 10))


def test_etsi_speed_rule():
    """Accelerating from rest at 0.9 m/s^2: a message each time the speed has changed by 0.5 m/s (56 steps)."""

    def accelerating(n, shape):
        out = np.zeros((6, *shape))
        t = n * DT
        out[0], out[2], out[4] = 0.45 * t * t, 0.9 * t, 0.9
        return out

    assert math.ceil(0.5 / (0.9 * DT)) == 56
    assert etsi_steps(accelerating, 300) == list(range(0, 300, 56))


def test_etsi_heading_rule():
    """1 m/s on a circle of radius 2 m turns 0.5 rad/s: 4 degrees every ceil(4 deg / (0.5 rad/s dt)) = 14 steps."""

    def circling(n, shape):
        out = np.zeros((6, *shape))
        phase = 0.5 * n * DT
        out[0], out[1] = 2 * math.sin(phase), 2 * (1 - math.cos(phase))
        out[2], out[3] = math.cos(phase), math.sin(phase)
        return out

    assert math.ceil(math.radians(4.0) / (0.5 * DT)) == 14
    assert etsi_steps(circling, 100) == list(range(0, 100, 14))


def test_etsi_new_message_when_a_vru_enters_coverage():
    """A VRU standing still that reappears in coverage is announced at once, not 5 s after its last message."""
    steps = etsi_steps(constant_velocity(0.0), 800, covered=lambda n: 100 <= n < 300 or n >= 400)
    assert steps == [100, 400]


# ---------------------------------------------------------------- RSU perception error


def test_rsu_noise_statistics():
    """Reported position and velocity errors: zero mean, the configured standard deviation (10^5 messages)."""
    spec = {"generation": {"rate_hz": 10}, "rsu_position_sigma_m": 0.5, "rsu_speed_sigma_mps": 0.3}
    params = channel_batch(spec, np.arange(1000))
    channel = RealisticChannel()
    channel.reset(params)
    shape = params.vru_valid.shape
    errors = []
    for n in range(0, 1000):
        truth = constant_velocity(1.0, 0.5, 3.0, -2.0)(n, shape)
        out = channel.deliver(n * DT, V2xMessages(np.ones(shape, bool), truth, np.zeros(shape), np.ones(shape, bool)))
        if n % 10 == 0:  # fresh messages (age 0)
            errors.append(out.kinematics[:4, :, 0] - truth[:4, :, 0])
    errors = np.concatenate(errors, axis=1)
    for row, sigma in zip(range(4), (0.5, 0.5, 0.3, 0.3), strict=True):
        assert abs(errors[row].mean()) < 4.5 * sigma / math.sqrt(errors.shape[1])
        assert abs(errors[row].std() / sigma - 1) < 4.5 / math.sqrt(2 * errors.shape[1])
    assert abs(np.corrcoef(errors[0], errors[2])[0, 1]) < 0.02


# ---------------------------------------------------------------- determinism


def test_same_seed_same_run_different_seed_different_run():
    spec = {"loss": {"model": "bernoulli", "probability": 0.3}, "jitter_s": 0.05, "rsu_position_sigma_m": 0.2}
    first = drive(channel_batch(spec, [5, 5, 6]), 300)
    second = drive(channel_batch(spec, [5]), 300)
    assert np.array_equal(first.message_step[:, 0], first.message_step[:, 1])
    assert np.array_equal(first.message_step[:, 0], second.message_step[:, 0])
    assert np.array_equal(first.x_m[:, 0], second.x_m[:, 0])
    assert not np.array_equal(first.message_step[:, 0], first.message_step[:, 2])


CHANNELS = [
    "ideal",
    "typical",
    "lossy",
    "bursty",
    "congested",
    "noisy",
    "etsi",
    {"latency_s": 0.2, "outages": [{"start_s": 2.5, "end_s": 3.0}], "rsu_speed_sigma_mps": 0.4},
]


@pytest.fixture(scope="module")
def channel_variants(paper_pedestrian_dict):
    """1,000 pedestrian-crossing variants: different speeds, triggers, seeds and channels, mostly V2X on."""
    rng = np.random.default_rng(4)
    variants = []
    for i in range(1000):
        data = copy.deepcopy(paper_pedestrian_dict)
        data["name"] = f"channel-{i}"
        data["sim"]["duration_s"] = 8.0
        data["sim"]["seed"] = int(rng.integers(0, 2**40))
        data["ego"]["cruise_speed_mps"] = round(float(rng.uniform(10.0, 20.0)), 3)
        data["vrus"][0]["trigger"] = {"at_time_s": round(float(rng.uniform(0.0, 2.5)), 3)}
        data["v2x"]["enabled"] = bool(rng.random() < 0.9)
        data["v2x"]["channel"] = CHANNELS[i % len(CHANNELS)]
        variants.append(scenario_from_mapping(data))
    return variants


@pytest.mark.parametrize("index", [0, 1, 2, 3, 4, 5, 6, 7, 501, 999])
def test_variant_alone_equals_variant_in_a_batch_of_1000(channel_variants, index, batch_of_1000):
    alone = metric_arrays(simulate([channel_variants[index]]).metrics)
    batch = metric_arrays(batch_of_1000.metrics)
    for name in sorted(batch.keys() - SCRATCH_FIELDS):
        assert np.array_equal(batch[name][index], alone[name][0], equal_nan=True), name


@pytest.fixture(scope="module")
def batch_of_1000(channel_variants):
    return simulate(channel_variants)


def test_batch_of_1000_has_varied_outcomes(batch_of_1000, channel_variants):
    collided = batch_of_1000.metrics.collided
    assert 0 < collided.sum() < len(channel_variants)
    assert isinstance(make_channel(batch_of_1000.params), RealisticChannel)


def test_threaded_kernel_equals_serial(monkeypatch):
    spec = {"loss": {"model": "gilbert_elliott", "p_good_to_bad": 0.1, "p_bad_to_good": 0.3}, "jitter_s": 0.03}
    params = channel_batch(spec, np.arange(64), vrus=2)
    serial = drive(params, 200, constant_velocity(1.2))
    monkeypatch.setattr(kernels, "PARALLEL_MIN_BATCH", 1)
    threaded = drive(params, 200, constant_velocity(1.2))
    assert np.array_equal(serial.message_step, threaded.message_step)
    assert np.array_equal(serial.x_m, threaded.x_m)


@settings(deadline=None, max_examples=40)
@given(
    latency=st.floats(0.0, 0.5),
    jitter=st.floats(0.0, 0.3),
    rate=st.floats(1.0, 100.0),
    probability=st.floats(0.0, 1.0),
    max_age=st.floats(0.0, 2.0),
    seed=st.integers(0, 2**40),
    start=st.integers(0, 100),
)
def test_channel_invariants(latency, jitter, rate, probability, max_age, seed, start):
    """Whatever the parameters: ages within [latency, max age], delays within [L, L + J] (to the step), the
    track never goes back in time, nothing before coverage + latency, and for a VRU at constant velocity the
    prediction is the truth."""
    max_age = max(max_age, latency + jitter)  # a shorter track age is rejected by the schema
    spec = {
        "generation": {"rate_hz": rate},
        "latency_s": latency,
        "jitter_s": jitter,
        "loss": {"model": "bernoulli", "probability": probability},
        "track_max_age_s": max_age,
    }
    params = channel_batch(spec, [seed, seed + 1], vrus=2)
    record = drive(params, 250, constant_velocity(2.0, -1.0, 5.0), covered=lambda n: n >= start)
    shown = record.received
    assert np.all(record.age_s[shown] >= latency - 1e-9)
    assert np.all(record.age_s[shown] <= max_age + 1e-9)
    assert not shown[: start + math.ceil(latency / DT - 1e-9)].any()
    truth = 5.0 + 2.0 * np.arange(250) * DT
    assert np.allclose(record.x_m[shown], np.broadcast_to(truth[:, None, None], shown.shape)[shown], atol=1e-9)
    for b in range(2):
        for k in range(2):
            got = deliveries(record, b, k)
            assert [g for _, g in got] == sorted({g for _, g in got})
            for n, g in got:
                assert math.ceil(latency / DT - 1e-9) <= n - g <= math.ceil((latency + jitter) / DT - 1e-9)
    assert np.all(record.channel.delivered <= record.channel.generated)


# ---------------------------------------------------------------- schema and profile files


def v2x_with(channel) -> dict:
    data = minimal_scenario_dict()
    data["v2x"] = {"enabled": True, "rsu": [0.0, 0.0], "channel": channel}
    return data


@pytest.mark.parametrize(
    ("channel", "message"),
    [
        ("perfect", "v2x.channel: unknown channel profile 'perfect'; expected one of: bursty, congested, etsi, ideal"),
        ({"latency_s": -0.1}, "v2x.channel.latency_s: Input should be greater than or equal to 0"),
        ({"jitter_s": -1}, "v2x.channel.jitter_s: Input should be greater than or equal to 0"),
        ({"loss": {"model": "bernoulli", "probability": 1.5}}, "v2x.channel.loss.probability: Input should be less"),
        ({"loss": {"model": "gilbert_elliott", "p_good_to_bad": 0.1}}, "v2x.channel.loss.p_bad_to_good: Field req"),
        ({"loss": {"model": "bursty"}}, "v2x.channel.loss: unknown loss model 'bursty'"),
        ({"loss": {"model": "distance", "d50_m": 50, "scale_m": 10, "probability": 0.1}}, "loss.probability: unknown"),
        ({"outages": [{"start_s": 2.0, "end_s": 1.0}]}, "v2x.channel.outages[0]: end_s must be greater than start_s"),
        ({"generation": {"mode": "sometimes"}}, "v2x.channel.generation.mode: Input should be 'every_step'"),
        ({"generation": {"rate_hz": 0}}, "v2x.channel.generation.rate_hz: Input should be greater than 0"),
        ({"track_max_age_s": -1}, "v2x.channel.track_max_age_s: Input should be greater than or equal to 0"),
        ({"latency": 0.1}, "v2x.channel.latency: unknown field"),
        (5, "v2x.channel: expected a profile name or a mapping of channel fields"),
    ],
)
def test_channel_errors_name_the_field(channel, message):
    with pytest.raises(UserInputError) as error:
        scenario_from_mapping(v2x_with(channel), "bad.yaml")
    assert message in str(error.value)


def test_channel_yaml_forms(tmp_path):
    """`channel: ideal` keeps working; a profile name and an inline spec load, and survive a dump."""
    for channel in ("ideal", "bursty", {"latency_s": 0.2, "loss": {"model": "bernoulli", "probability": 0.1}}):
        path = tmp_path / "s.yaml"
        path.write_text(yaml.safe_dump(v2x_with(channel)))
        scenario = load_scenario(path)
        assert scenario_from_mapping(scenario.model_dump(mode="json")) == scenario
        expected = V2X_PROFILES[channel] if isinstance(channel, str) else ChannelSpec.model_validate(channel)
        assert scenario.v2x.channel_spec == expected
    assert scenario_from_mapping(minimal_scenario_dict()).v2x.channel == "ideal"


def test_load_profiles(tmp_path):
    path = tmp_path / "profiles.yaml"
    path.write_text("slow:\n  latency_s: 0.5\n  loss: {model: bernoulli, probability: 0.2}\nfast: {latency_s: 0.01}\n")
    profiles = load_profiles(path)
    assert profiles["slow"].latency_s == 0.5 and profiles["slow"].loss.probability == 0.2
    assert profiles["fast"].generation.mode == "periodic"
    path.write_text(
        "slow:\n  latency_s: -0.5\ntypical: {}\nodd: 3\nworse:\n  loss: {model: bernoulli, probability: 2}\n"
    )
    with pytest.raises(UserInputError) as error:
        load_profiles(path)
    text = str(error.value)
    assert text.startswith(f"{path}: invalid channel profiles")
    assert "slow.latency_s: Input should be greater than or equal to 0" in text
    assert "typical: is a built-in profile" in text
    assert "odd: expected a mapping of channel fields" in text
    assert "worse.loss.probability: Input should be less than or equal to 1" in text
    with pytest.raises(UserInputError, match="no such profile file"):
        load_profiles(tmp_path / "missing.yaml")


def test_a_track_age_shorter_than_the_delay_is_rejected():
    """Messages older than the track age on arrival would be dropped silently: the schema refuses it."""
    from pydantic import ValidationError

    from vrusim.scenario.v2x import ChannelSpec

    with pytest.raises(ValidationError, match="track_max_age_s"):
        ChannelSpec(latency_s=0.8, jitter_s=0.3)  # default track age 1.0 s < 1.1 s
    assert ChannelSpec(latency_s=0.8, jitter_s=0.3, track_max_age_s=1.1).track_max_age_s == 1.1


@pytest.mark.parametrize("compiled", [True, False])
def test_delays_beyond_the_run_keep_a_queue_of_the_run_and_deliver_nothing(paper_pedestrian, compiled):
    """10 s of latency and 10 s of jitter in a 0.5 s run (50 steps): nothing is delivered, exactly as with the
    latency of the whole run, and the queue holds the run's steps + 2 (2,002 before; 89 GiB at dt = 1e-8 s)."""
    paper_pedestrian["v2x"]["enabled"] = True
    paper_pedestrian["sim"]["duration_s"] = 0.5
    runs = {}
    for delay in (10.0, 0.5):
        jitter = 10.0 if delay == 10.0 else 0.0
        paper_pedestrian["v2x"]["channel"] = {
            "generation": {"mode": "every_step"},
            "latency_s": delay,
            "jitter_s": jitter,
            "track_max_age_s": 30.0,
        }
        scenario = scenario_from_mapping(paper_pedestrian)
        runs[delay] = simulate([scenario], compiled=compiled)
        channel = RealisticChannel()
        channel.reset(pack([scenario]))
        assert channel.buf_kin.shape[2] == 52
    assert np.array_equal(runs[10.0].metrics.values, runs[0.5].metrics.values, equal_nan=True)
    assert np.isnan(runs[10.0].metrics.first_v2x_s[0])
