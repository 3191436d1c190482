"""Environment steps per second: `VruEnv` (one scenario) against `VruVectorEnv` (N sub-environments, one batch).

    python benchmarks/bench_gym.py [--envs 1000] [--steps 2000] [--scenario paper:pedestrian] [--v2x]
                                   [--policy random|driving]

Both run the same random policy, with resets (autoreset in the vector env) included in the timing: `random`
draws uniformly over the action space (most egos brake to a stop, so most episodes end together, truncated);
`driving` draws from [-3, 2] m/s^2 (egos keep moving; episodes end at scattered steps by collision or route
end, which splits the vector env into many cohorts). Prints env-steps/s of each, the per-environment-step
speed-up, and the mean number of batches (cohorts) the vector env stepped per call.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from vrusim.gym import VruEnv, VruVectorEnv

POLICIES = {"random": None, "driving": (-3.0, 2.0)}
"""Policy name → range of the uniform acceleration draw, m/s^2 (None: the whole action space)."""


def _sampler(space, policy: str, seed: int):
    rng = np.random.default_rng(seed)
    bounds = POLICIES[policy]
    low, high = (space.low, space.high) if bounds is None else bounds
    return lambda: rng.uniform(low, high, size=space.shape)


def single_rate(scenario: str, v2x: bool, steps: int, policy: str = "random", seed: int = 0) -> float:
    """Env-steps per second of one `VruEnv` under random actions (reset after each episode)."""
    env = VruEnv(scenario, v2x=v2x)
    sample = _sampler(env.action_space, policy, seed)
    env.reset(seed=seed)
    env.step(sample())  # compile / load caches outside the timing
    env.reset(seed=seed)
    start = time.perf_counter()
    for _ in range(steps):
        _, _, terminated, truncated, _ = env.step(sample())
        if terminated or truncated:
            env.reset()
    return steps / (time.perf_counter() - start)


def vector_rate(
    scenario: str, v2x: bool, envs: int, steps: int, policy: str = "random", seed: int = 0
) -> tuple[float, float]:
    """(env-steps per second, mean cohorts per call) of a `VruVectorEnv` of `envs` sub-environments."""
    env = VruVectorEnv(envs, scenario=scenario, v2x=v2x)
    sample = _sampler(env.action_space, policy, seed)
    env.reset(seed=seed)
    env.step(sample())
    env.reset(seed=seed)
    cohorts = 0
    start = time.perf_counter()
    for _ in range(steps):
        env.step(sample())
        cohorts += env.cohorts
    return envs * steps / (time.perf_counter() - start), cohorts / steps


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--envs", type=int, default=1000)
    parser.add_argument("--steps", type=int, default=2000, help="steps of each env (single and vector)")
    parser.add_argument("--scenario", default="paper:pedestrian")
    parser.add_argument("--v2x", action="store_true")
    parser.add_argument("--policy", choices=sorted(POLICIES), default="random")
    args = parser.parse_args()
    single = single_rate(args.scenario, args.v2x, args.steps, args.policy)
    vector, cohorts = vector_rate(args.scenario, args.v2x, args.envs, args.steps, args.policy)
    v2x = "on" if args.v2x else "off"
    print(f"scenario {args.scenario} (v2x {v2x}), {args.policy} policy, {args.steps} steps of each env")
    print(f"single env:           {single:12,.0f} env-steps/s  ({1e6 / single:.1f} us/step)")
    print(f"vector env, N={args.envs:<6}  {vector:12,.0f} env-steps/s  ({1e6 / vector:.2f} us/env-step)")
    print(f"speed-up per env-step: {vector / single:.0f}x   (mean cohorts per call {cohorts:.2f})")
    print(f"numpy {np.__version__}")


if __name__ == "__main__":
    main()
