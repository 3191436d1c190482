"""Gymnasium environments: API conformance, determinism, exact agreement with the batch engine, vector env."""

from __future__ import annotations

import subprocess
import sys
import warnings

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import vrusim.gym
from conftest import PAPER_DIR
from vrusim.engine.simulate import simulate
from vrusim.errors import UserInputError
from vrusim.gym import VruEnv, VruVectorEnv
from vrusim.gym.episodes import SUMMARY_COLUMNS
from vrusim.metrics.columns import result_columns
from vrusim.planners.registry import make_planner
from vrusim.scenario.schema import Scenario

GENERIC_KWARGS = {"scenario": "CPNA-25/20kph/day"}
PER_VRU_COLUMNS = ("min_ttc_vru0_s", "min_clearance_vru0_m")
"""The per-VRU measures' columns of a one-VRU scenario, also in `info["metrics"]`."""


def _equal(a, b) -> bool:
    """Bit-equal, NaN equal to NaN."""
    return bool(a == b) or (isinstance(a, float) and np.isnan(a) and np.isnan(b))


def _item(value):
    """A NumPy scalar as a Python one (the outcome, a string, as it is)."""
    return value if isinstance(value, str) else value.item()


@pytest.mark.parametrize("env_id", sorted(vrusim.gym.ENV_IDS))
def test_check_env_passes_for_every_registered_id(env_id):
    kwargs = GENERIC_KWARGS if env_id == "vrusim/Scenario-v0" else {}
    env = gymnasium.make(env_id, **kwargs)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # advice only: "use a symmetric, normalised Box" (ours is in m/s^2)
        check_env(env.unwrapped, skip_render_check=True)


def test_scenario_env_takes_yaml_paths_and_paper_keys():
    env = gymnasium.make("vrusim/Scenario-v0", scenario=str(PAPER_DIR / "escooter_leading.yaml"), v2x=True)
    assert env.unwrapped.scenario.v2x.enabled
    assert env.unwrapped.scenario == VruEnv("paper:escooter", v2x=True).scenario
    with pytest.raises(UserInputError, match="catalogue test id"):
        VruEnv("CPNA-25/99kph/day")


def test_random_episode_ends_with_finite_rewards_inside_the_space():
    env = VruEnv("paper:motorcyclist", v2x=True)
    env.action_space.seed(1)
    obs, _ = env.reset(seed=1)
    rewards, terminated, truncated, info = [], False, False, {}
    while not (terminated or truncated):
        assert env.observation_space.contains(obs)
        obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
        rewards.append(reward)
    assert env.observation_space.contains(obs)
    assert np.isfinite(rewards).all() and len(rewards) > 10
    assert set(info["metrics"]) == {*SUMMARY_COLUMNS, *PER_VRU_COLUMNS}
    assert info["metrics"]["min_ttc_vru0_s"] == info["metrics"]["min_ttc_s"] or np.isnan(info["metrics"]["min_ttc_s"])
    with pytest.raises(RuntimeError, match="reset"):
        env.step(env.action_space.sample())


def test_reset_with_a_seed_is_deterministic():
    def rollout() -> list:
        env = VruEnv("paper:pedestrian", v2x=True)
        env.action_space.seed(7)
        out = [env.reset(seed=7)[0]]
        for _ in range(200):
            obs, reward, *_ = env.step(env.action_space.sample())
            out += [obs, reward]
        out.append(env.reset(seed=7)[0])
        return out

    first, second = rollout(), rollout()
    assert all(np.array_equal(a, b) for a, b in zip(first, second, strict=True))
    assert np.array_equal(first[0], first[-1])


@pytest.mark.parametrize(
    ("source", "v2x"),
    [(f"paper:{case}", v2x) for case in ("pedestrian", "escooter", "motorcyclist") for v2x in (False, True)]
    + [("CPNA-25/20kph/day", False), ("CBLA-50/25kph/day", True)],
)
def test_env_driven_by_the_fsm_planner_reproduces_simulate_exactly(source, v2x):
    env = VruEnv(source, v2x=v2x)
    env.reset(seed=0)
    planner = make_planner("fsm")
    planner.reset(env.params)
    info, steps = {}, 0
    while "metrics" not in info:
        _, _, _, _, info = env.step(planner.act(env.planner_observation))
        steps += 1
    run = simulate([env.scenario])
    expected = result_columns(run)
    assert steps == run.steps
    for name in SUMMARY_COLUMNS:
        assert _equal(info["metrics"][name], _item(expected[name][0])), name


def _noisy_sensor(scenario: Scenario) -> Scenario:
    """The scenario with a realistic sensor: latency, missed detections and noise (keyed random draws)."""
    data = scenario.model_dump()
    data["sensor"].update(detection_probability=0.8, position_sigma_m=0.3, latency_s=0.1)
    return Scenario.model_validate(data)


def test_vector_env_equals_single_envs_given_the_same_actions():
    scenarios = [
        VruEnv("paper:pedestrian").scenario,
        _noisy_sensor(VruEnv("paper:pedestrian", v2x=True).scenario),
        VruEnv("paper:escooter", v2x=True).scenario,
        VruEnv("paper:motorcyclist").scenario,
    ]
    vector = VruVectorEnv(scenario=scenarios)
    singles = [VruEnv(s) for s in scenarios]
    obs, _ = vector.reset(seed=0)
    assert np.array_equal(obs, np.stack([env.reset(seed=0)[0] for env in singles]))
    rng = np.random.default_rng(0)
    ended = np.zeros(len(singles), dtype=bool)
    episodes = most_cohorts = 0
    for _ in range(1500):
        actions = rng.uniform(-3.0, 2.0, size=(len(singles), 1))
        obs, rewards, terminated, truncated, infos = vector.step(actions)
        for i, env in enumerate(singles):
            if ended[i]:  # next-step autoreset: the vector env reset this one and ignored its action
                expected, reward, term, trunc, info = (*env.reset()[:1], 0.0, False, False, {})
            else:
                expected, reward, term, trunc, info = env.step(actions[i])
            assert np.array_equal(obs[i], expected) and rewards[i] == reward
            assert (terminated[i], truncated[i]) == (term, trunc)
            if "metrics" in info:
                episodes += 1
                assert infos["_metrics"][i]
                assert all(_equal(_item(infos["metrics"][k][i]), v) for k, v in info["metrics"].items())
            ended[i] = term or trunc
        most_cohorts = max(most_cohorts, vector.cohorts)
    assert episodes >= 4 and most_cohorts >= 2 and vector.observation_space.contains(obs)


def test_actions_are_clipped_to_the_ego_limits_and_must_be_finite():
    def first_step(action) -> np.ndarray:
        env = VruEnv("paper:escooter")
        env.reset()
        return env.step(action)[0]

    env = VruEnv("paper:escooter")
    low, high = env.action_space.low, env.action_space.high
    assert low[0] == -env.scenario.ego.max_decel_mps2 and high[0] == env.scenario.ego.max_accel_mps2
    assert np.array_equal(first_step([1e3]), first_step(high))
    assert np.array_equal(first_step([-1e3]), first_step(low))
    assert not np.array_equal(first_step(low), first_step(high))
    env.reset()
    with pytest.raises(ValueError, match="finite"):
        env.step([np.nan])


def test_make_vec_uses_the_batch_engine_with_next_step_autoreset():
    envs = gymnasium.make_vec(
        "vrusim/PaperPedestrian-v0", num_envs=3, vectorization_mode="vector_entry_point", v2x=True
    )
    assert isinstance(envs, VruVectorEnv)
    assert envs.metadata["autoreset_mode"] == gymnasium.vector.AutoresetMode.NEXT_STEP
    obs, _ = envs.reset(seed=0)
    assert obs.shape == envs.observation_space.shape == (3, envs.single_observation_space.shape[0])
    assert envs.action_space.shape == (3, 1)
    envs.step(np.zeros((3, 1)))
    before, _ = envs.reset(options={"reset_mask": np.array([True, False, False])})
    assert envs.cohorts == 2 and np.array_equal(before[0], obs[0]) and not np.array_equal(before[1], obs[1])


def test_rgb_array_frames_follow_the_episode_at_a_fixed_size():
    from matplotlib.colors import to_rgb

    from vrusim.viz.style import EGO_FACE

    env = gymnasium.make("vrusim/PaperPedestrian-v0", render_mode="rgb_array").unwrapped
    assert env.metadata["render_fps"] == pytest.approx(100.0)  # one frame per 0.01 s step
    env.reset(seed=0)
    first = env.render()
    assert first.dtype == np.uint8 and first.ndim == 3 and first.shape[2] == 3
    ego = np.array(to_rgb(EGO_FACE)) * 255
    assert (np.abs(first.astype(float) - ego).max(axis=2) < 8).sum() > 50  # the ego rectangle is drawn
    for _ in range(150):
        env.step(np.array([0.0], dtype=np.float32))
    later = env.render()
    assert later.shape == first.shape  # video recorders need one frame size
    assert not np.array_equal(later, first)  # time label and positions moved on
    with pytest.raises(ValueError, match="render_mode"):
        VruEnv("paper:pedestrian", render_mode="rgb")  # human mode: tests/test_gym_render.py
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # advice only, as above
        check_env(gymnasium.make("vrusim/PaperEscooter-v0", render_mode="rgb_array").unwrapped)


def test_a_registered_metric_is_in_the_episode_summary():
    """A plug-in metric (tests/extra_metric.py) reaches `info["metrics"]` without a change to the Gym."""
    import extra_metric

    extra_metric.register()
    try:
        env = VruEnv("paper:pedestrian", v2x=True)
        env.reset(seed=3)
        terminated = truncated = False
        while not (terminated or truncated):
            _, _, terminated, truncated, info = env.step(np.array([0.0], dtype=np.float32))
    finally:
        extra_metric.unregister()
    assert set(info["metrics"]) == {*SUMMARY_COLUMNS, *PER_VRU_COLUMNS, "mean_speed_mps", "stopped_at_end"}
    assert isinstance(info["metrics"]["stopped_at_end"], bool) and info["metrics"]["mean_speed_mps"] > 0


_NEW_KERNEL_VERSIONS = """
import sys, gymnasium, vrusim.gym
from vrusim.api.compiling import CompileTask, run_task
from vrusim.kernels import BatchKernel

def versions():
    kernels = {}
    for module in [m for name, m in sys.modules.items() if name.startswith("vrusim.")]:
        for name, value in vars(module).items():
            if isinstance(value, BatchKernel) and value._serial is not None:
                kernels[f"{value.function.__module__}.{name}"] = len(value._serial.signatures)
    return kernels

run_task(CompileTask(("per-step",), "none"))  # `vrusim compile --part per-step --planner none`
before = versions()
env = gymnasium.make("vrusim/PaperPedestrian-v0", v2x=True)
env.reset(seed=0)
for _ in range(3):
    env.step(env.action_space.sample())
envs = gymnasium.make_vec("vrusim/PaperPedestrian-v0", num_envs=3, vectorization_mode="vector_entry_point")
envs.reset(seed=0)
envs.step(envs.action_space.sample())
after = versions()
print(sorted(name for name, count in after.items() if count > before.get(name, 0)))
"""


def test_environments_need_no_kernel_version_that_vrusim_compile_leaves_out():
    """After the per-step path's warm-up (`vrusim compile --part per-step`), stepping the environments adds no
    version of any batch kernel: they pass the argument types the engine does (a read-only ego speed compiled
    another `ttc_batch`)."""
    done = subprocess.run([sys.executable, "-c", _NEW_KERNEL_VERSIONS], capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "[]"
