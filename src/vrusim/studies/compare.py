"""Compare planners and V2X settings on one scenario: every combination, many seeds, one table.

Each combination runs as one batch of `seeds` variants (seeds first_seed … first_seed + seeds − 1, by default
0 … seeds − 1, for the channel's and sensor's random numbers); a deterministic setting gives identical variants,
a stochastic one a distribution. The summary per combination: collision probability with its Wilson 95 %
interval, mean impact speed over the collisions, minimum TTC, first detection times and mean safety / efficiency
/ comfort scores.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from vrusim.engine.simulate import simulate
from vrusim.errors import UserInputError
from vrusim.limits import check_limit
from vrusim.metrics.summary import summary_rows
from vrusim.planners.registry import make_planner
from vrusim.scenario.loading import scenario_from_mapping
from vrusim.scenario.schema import MAX_SEED, Scenario

V2X_OFF = "off"
"""The `--v2x` value that switches V2X off."""
V2X_ON = "on"
"""The `--v2x` value that switches V2X on with the scenario's own channel; any other value names a profile."""


@dataclass(frozen=True)
class Combination:
    """One planner with one V2X setting."""

    planner: str
    v2x: str


def wilson_interval(successes: int, trials: int, z: float = 1.959964) -> tuple[float, float]:
    """Wilson score interval of a binomial proportion (Wilson 1927), 95 % by default."""
    if trials == 0:
        return 0.0, 1.0
    p = successes / trials
    denominator = 1 + z * z / trials
    centre = (p + z * z / (2 * trials)) / denominator
    half = z * math.sqrt(p * (1 - p) / trials + z * z / (4 * trials * trials)) / denominator
    low = 0.0 if successes == 0 else max(0.0, centre - half)  # exact ends: rounding would give 1e-17 or 1 − 1e-16
    high = 1.0 if successes == trials else min(1.0, centre + half)
    return low, high


def variant(base: Scenario, combination: Combination, seed: int, channel: dict | str | None = None) -> Scenario:
    """The base scenario with the combination's planner, V2X setting and seed (validated again).

    The scenario's `planner.params` apply to its own planner; any other planner runs with its defaults.
    `channel` overrides the profile by an inline channel specification (user profiles from a file).
    """
    data = base.model_dump()
    if combination.planner != base.planner.name:  # the file's parameters belong to its own planner
        data["planner"] = {"name": combination.planner, "params": {}}
    data["sim"]["seed"] = seed
    if combination.v2x == V2X_OFF:
        data["v2x"]["enabled"] = False
    else:
        data["v2x"]["enabled"] = True
        if combination.v2x != V2X_ON:
            data["v2x"]["channel"] = channel if channel is not None else combination.v2x
    return scenario_from_mapping(data, f"{base.name} [{combination.planner}, v2x {combination.v2x}]")


def compare(
    base: Scenario,
    planners: Sequence[str],
    v2x: Sequence[str],
    seeds: int = 1,
    channels: dict[str, dict] | None = None,
    first_seed: int = 0,
) -> list[dict]:
    """One summary row per (planner, V2X setting) over `seeds` seeded variants (seeds `first_seed` onwards)."""
    if seeds < 1:
        raise UserInputError("--seeds: expected a positive number of seeds")
    if not 0 <= first_seed <= MAX_SEED - (seeds - 1):
        raise UserInputError(
            f"--seed, --seeds: seeds {first_seed:,} to {first_seed + seeds - 1:,} leave the seed range 0 to 2^63 − 1; "
            f"give --seed from 0 to {MAX_SEED - (seeds - 1):,} with --seeds {seeds:,}"
        )
    what = f"--seeds: {seeds:,} seeds x {len(v2x)} V2X settings x {len(planners)} planners"
    check_limit("compare_runs", seeds * len(v2x) * len(planners), what)
    if base.v2x.rsu is None and any(name != V2X_OFF for name in v2x):
        raise UserInputError("--v2x: the scenario has no roadside unit (v2x.rsu); only 'off' is possible")
    from vrusim.scenario.v2x import V2X_PROFILES

    known = [V2X_OFF, V2X_ON, *V2X_PROFILES, *(channels or {})]
    unknown = [name for name in v2x if name not in known]
    if unknown:
        raise UserInputError(f"--v2x: unknown setting {unknown[0]!r}; expected one of: {', '.join(known)}")
    for name in planners:
        try:
            make_planner(name)
        except UserInputError as error:
            raise UserInputError(str(error).replace("planner.name:", "--planner:", 1)) from None
    rows = []
    for planner in planners:
        combinations = [Combination(planner, name) for name in v2x]
        scenarios = [
            variant(base, combination, seed, (channels or {}).get(combination.v2x))
            for combination in combinations
            for seed in range(first_seed, first_seed + seeds)
        ]
        summaries = summary_rows(simulate(scenarios, planner=make_planner(planner)))
        for index, combination in enumerate(combinations):
            rows.append(_summarise(combination, summaries[index * seeds : (index + 1) * seeds]))
    return rows


def _mean(values: list[float | None]) -> float | None:
    present = [v for v in values if v is not None]
    return round(sum(present) / len(present), 4) if present else None


def _summarise(combination: Combination, runs: list[dict]) -> dict:
    collisions = sum(run["collided"] for run in runs)
    low, high = wilson_interval(collisions, len(runs))
    impacts = [run["impact_ego_speed_mps"] for run in runs if run["collided"]]
    ttcs = [run["min_ttc_s"] for run in runs if run["min_ttc_s"] is not None]
    return {
        "planner": combination.planner,
        "v2x": combination.v2x,
        "runs": len(runs),
        "collisions": collisions,
        "collision_probability": round(collisions / len(runs), 4),
        "collision_probability_95": [round(low, 4), round(high, 4)],
        "mean_impact_speed_mps": _mean(impacts),
        "min_ttc_s": round(min(ttcs), 4) if ttcs else None,
        "mean_first_sensor_detection_s": _mean([run["first_sensor_detection_s"] for run in runs]),
        "mean_first_v2x_message_s": _mean([run["first_v2x_message_s"] for run in runs]),
        "safety": _mean([run["safety"] for run in runs]),
        "efficiency": _mean([run["efficiency"] for run in runs]),
        "comfort": _mean([run["comfort"] for run in runs]),
    }
