"""The laboratory's verification of 2026 predictions, simulated as a Monte Carlo (FC26 §4.2, §4.3.2, §5.3.4).

Each draw is one lab visit: per FC scenario the lab picks 3-5 standard and 2 extended cells at random among the
non-red, non-corner-case predictions (FC26 §4.2.1, §4.1.2; uniform, as R26 `select_test_points` does) and runs
each once with test tolerances (VUT speed 0..+1 km/h, VUT lateral ±0.05 m, target timing ±0.1 s: FC26 §4.3.2).
A test passes when its outcome confirms the predicted colour within ±2 km/h or beats it (§4.2.4, §5.3.4); the
passed count scales the range's points (§5.3.4 table). LSC cells are all verified (R26 `get_all_lsc_points`)
and score by their measured colour. Robustness: one claimed layer is tested; any failed standard test loses
its share (R26 `compute_loadcase_score`; vrusim does not simulate the layer itself).

Simulation cost: `simulate_cells` runs every eligible cell's N perturbed variants once (one batch); draws then
resample those outcomes, so 1,000 draws cost one batch plus array work.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from vrusim.engine.simulate import simulate
from vrusim.errors import UserInputError
from vrusim.metrics.summary import summary_rows
from vrusim.ncap.rating2026 import Assessment2026, CellResult2026
from vrusim.ncap.rating2026 import tables as t
from vrusim.ncap.rating2026.colours import KPH, accepted, colour_of, kpi_of
from vrusim.planners.registry import make_planner
from vrusim.scenario.schema import Scenario


@dataclass(frozen=True)
class Perturbation:
    """One run of a verification cell within the test tolerances."""

    test_id: str
    vut_speed_delta_kph: float
    lateral_offset_m: float
    target_timing_s: float


Outcome = Mapping[str, Any]
"""A run's result: `collided`, `impact_speed_mps`, `target_longitudinal_speed_mps`, `warning_ttc_s`."""
SimulateCells = Callable[[Sequence[Perturbation]], Sequence[Outcome]]


@dataclass(frozen=True)
class Spread:
    mean: float
    std: float
    p5: float
    p95: float

    @classmethod
    def of(cls, values: np.ndarray) -> Spread:
        return cls(
            float(values.mean()), float(values.std()), float(np.percentile(values, 5)), float(np.percentile(values, 95))
        )


@dataclass(frozen=True)
class VerificationReport:
    """Pass probability per cell and the points after verification scaling, as a distribution over draws."""

    n_draws: int
    n_perturbations: int
    seed: int
    method: str
    pass_probability: dict[str, float]
    scenarios: dict[str, Spread]
    sub_elements: dict[str, Spread]
    predicted: dict[str, float]

    def to_dict(self) -> dict[str, Any]:
        return {
            "n_draws": self.n_draws,
            "n_perturbations": self.n_perturbations,
            "seed": self.seed,
            "method": self.method,
            "pass_probability": self.pass_probability,
            "scenarios": {k: v.__dict__ for k, v in self.scenarios.items()},
            "sub_elements": {k: v.__dict__ for k, v in self.sub_elements.items()},
            "predicted": self.predicted,
            "unverified": list(t.UNVERIFIED),
        }


def eligible_cells(assessment: Assessment2026) -> dict[str, dict[str, list[CellResult2026]]]:
    """Verification candidates per scenario and range: predicted non-red, not a corner case (FC26 §4.2, §4.1.2)."""
    out: dict[str, dict[str, list[CellResult2026]]] = {}
    for cell in assessment.cells:
        if cell.colour == "red" or cell.corner_case or cell.range == "robustness":
            continue
        out.setdefault(cell.scenario, {"standard": [], "extended": []})[cell.range].append(cell)
    return out


def sample_lab(assessment: Assessment2026, rng: np.random.Generator) -> dict[str, dict[str, list[CellResult2026]]]:
    """One lab sample: per FC scenario N standard (FC26 §4.2.1 table) and 2 extended cells, uniformly without
    replacement; every eligible LSC cell (R26)."""
    sample = {}
    for scenario, ranges in eligible_cells(assessment).items():
        if scenario in t.LSC_SCENARIOS:
            sample[scenario] = {"standard": list(ranges["standard"]), "extended": []}
            continue
        wanted = {"standard": t.STANDARD_VERIFICATION_TESTS[scenario], "extended": t.EXTENDED_VERIFICATION_TESTS}
        sample[scenario] = {
            name: [cells[i] for i in rng.permutation(len(cells))[: wanted[name]]] for name, cells in ranges.items()
        }
    return sample


def perturbations(cells: Sequence[CellResult2026], n: int, rng: np.random.Generator) -> list[Perturbation]:
    """N runs per cell, tolerances drawn uniformly within FC26 §4.3.2's bounds (t.VERIFICATION_TOLERANCES)."""
    tol = t.VERIFICATION_TOLERANCES
    size = (len(cells), n)
    dv = rng.uniform(0.0, tol["vut_speed_kph_max"], size)
    dy = rng.uniform(-tol["vut_lateral_m"], tol["vut_lateral_m"], size)
    dt = rng.uniform(-tol["target_timing_s"], tol["target_timing_s"], size)
    return [
        Perturbation(cell.test_id, float(dv[i, k]), float(dy[i, k]), float(dt[i, k]))
        for i, cell in enumerate(cells)
        for k in range(n)
    ]


def judge(cell: CellResult2026, outcome: Outcome) -> tuple[bool, str]:
    """(does the run confirm the prediction, the run's measured colour) for a verification cell."""
    row = {"official_scenario": cell.scenario, "vut_speed_kph": cell.vut_speed_kph, **outcome}
    kpi = kpi_of(row, cell.criterion)
    measured = colour_of(row, cell.criterion, kpi)
    if cell.criterion == t.MITIGATION:
        return accepted(cell.colour, float(kpi or 0.0), float(cell.vut_speed_kph or 0.0)), measured
    return t.COLOURS.index(measured) <= t.COLOURS.index(cell.colour), measured


def monte_carlo(
    assessment: Assessment2026,
    simulate_cells: SimulateCells,
    n_draws: int = 1000,
    n_perturbations: int = 16,
    seed: int = 0,
    method: str = "VTA",
) -> VerificationReport:
    """Simulate `n_draws` lab verifications of the assessment's predictions; see the module docstring."""
    if n_draws < 1 or n_perturbations < 1:
        raise UserInputError("n_draws / n_perturbations: positive integers expected")
    if method not in t.PREDICTION_METHODS:
        raise UserInputError(f"method: expected one of {', '.join(t.PREDICTION_METHODS)}, got {method!r}")
    rng = np.random.default_rng(seed)
    pools = eligible_cells(assessment)
    cells = [c for ranges in pools.values() for name in ("standard", "extended") for c in ranges[name]]
    runs = perturbations(cells, n_perturbations, rng)
    outcomes = list(simulate_cells(runs)) if runs else []
    if len(outcomes) != len(runs):
        raise UserInputError(f"simulate_cells: returned {len(outcomes)} outcomes for {len(runs)} runs")
    passes = np.zeros((len(cells), n_perturbations), bool)
    weights = np.zeros((len(cells), n_perturbations))
    for i, cell in enumerate(cells):
        for k in range(n_perturbations):
            ok, measured = judge(cell, outcomes[i * n_perturbations + k])
            passes[i, k] = ok
            weights[i, k] = t.STANDARD_SUB_SCORE[measured]
    index = {id(c): i for i, c in enumerate(cells)}
    per_scenario: dict[str, np.ndarray] = {}
    for scenario, points in assessment.scenarios.items():
        pool = pools.get(scenario, {"standard": [], "extended": []})
        if scenario in t.LSC_SCENARIOS:
            per_scenario[scenario] = _lsc_draws(assessment, scenario, pool, index, weights, n_draws, rng)
            continue
        scaled = []
        for name, total in (("standard", points.standard), ("extended", points.extended)):
            rows = np.array([index[id(c)] for c in pool[name]], int)
            wanted = t.STANDARD_VERIFICATION_TESTS[scenario] if name == "standard" else t.EXTENDED_VERIFICATION_TESTS
            n = min(wanted, len(rows))
            passed = _passed_draws(rows, n, passes, n_draws, rng)
            table = t.VERIFICATION_SCALE_PCT[name][method][n]
            scaled.append(total * np.array([table[int(p)] for p in passed]) / 100.0)
            if name == "standard":
                all_passed = passed == n
        robustness = np.where(all_passed, points.robustness, points.robustness - _tested_share(assessment, scenario))
        floor = t.ROBUSTNESS_MIN_STANDARD_SHARE * t.TOTAL_POINTS[scenario]["standard"]
        robustness = np.where(np.round(scaled[0], 6) >= round(floor, 6), np.maximum(robustness, 0.0), 0.0)
        per_scenario[scenario] = scaled[0] + scaled[1] + robustness
    sub_elements = {
        name: sum((per_scenario[s] for s in members if s in per_scenario), np.zeros(n_draws))
        for name, members in t.SUB_ELEMENTS.items()
        if any(s in per_scenario for s in members)
    }
    return VerificationReport(
        n_draws=n_draws,
        n_perturbations=n_perturbations,
        seed=seed,
        method=method,
        pass_probability={c.test_id: float(passes[i].mean()) for i, c in enumerate(cells)},
        scenarios={k: Spread.of(v) for k, v in per_scenario.items()},
        sub_elements={k: Spread.of(v) for k, v in sub_elements.items()},
        predicted={k: p.total for k, p in assessment.scenarios.items()},
    )


def _passed_draws(rows: np.ndarray, n: int, passes: np.ndarray, n_draws: int, rng: np.random.Generator) -> np.ndarray:
    """Passed tests per draw: n cells sampled without replacement, one random perturbation each."""
    if n == 0:
        return np.zeros(n_draws, int)
    picked = rows[np.argsort(rng.random((n_draws, len(rows))), axis=1)[:, :n]]
    runs = rng.integers(0, passes.shape[1], size=picked.shape)
    return passes[picked, runs].sum(axis=1)


def _tested_share(assessment: Assessment2026, scenario: str) -> float:
    """Points of the one robustness layer the lab tests: total / applicable layers (0 without claims)."""
    column = t.ROBUSTNESS_COLUMN.get(scenario, "")
    if not assessment.robustness_claims.get(column):
        return 0.0
    return t.TOTAL_POINTS[scenario].get("robustness", 0.0) / len(t.APPLICABLE_LAYERS[column])


def _lsc_draws(
    assessment: Assessment2026,
    scenario: str,
    pool: Mapping[str, Sequence[CellResult2026]],
    index: Mapping[int, int],
    weights: np.ndarray,
    n_draws: int,
    rng: np.random.Generator,
) -> np.ndarray:
    """LSC points per draw: every verified cell scores its measured colour, the others their prediction (red, or
    corner cases at 0); mean over the grid × points (R26 `compute_lsc_loadcase_score`)."""
    all_cells = [c for c in assessment.cells_of(scenario) if c.range != "robustness"]
    rows = np.array([index[id(c)] for c in pool["standard"]], int)
    total = np.zeros(n_draws)
    if rows.size:
        runs = rng.integers(0, weights.shape[1], size=(n_draws, rows.size))
        total = weights[rows[None, :], runs].sum(axis=1)
    return total / len(all_cells) * t.TOTAL_POINTS[scenario]["standard"]


def perturbed_scenario(scenario: Scenario, run: Perturbation) -> Scenario:
    """The scenario with the run's tolerances applied: VUT speed + dv, VUT start y + dy, the first target's
    trigger delayed by dt (a route-distance trigger moves by dt × VUT speed)."""
    speed = scenario.ego.cruise_speed_mps + run.vut_speed_delta_kph * KPH
    changes: dict[str, Any] = {
        "ego.cruise_speed_mps": speed,
        "ego.start.y_m": scenario.ego.start.y_m + run.lateral_offset_m,
    }
    if scenario.ego.initial_speed_mps is not None and scenario.ego.initial_speed_mps > 0:
        changes["ego.initial_speed_mps"] = speed
    if scenario.vrus:
        trigger = scenario.vrus[0].trigger
        if trigger.ego_route_m is not None:
            changes["vrus[0].trigger.ego_route_m"] = max(trigger.ego_route_m + run.target_timing_s * speed, 0.0)
        elif trigger.at_time_s is not None:
            changes["vrus[0].trigger.at_time_s"] = max(trigger.at_time_s + run.target_timing_s, 0.0)
    return scenario.replace(**changes)


def vrusim_simulator(scenarios: Mapping[str, Scenario], planner: str = "fsm") -> SimulateCells:
    """A `simulate_cells` running vrusim: `scenarios` maps test_id -> its built Scenario
    (`ncap.build.build_test(test).scenario`); all perturbed runs go through one `simulate` batch."""

    def simulate_cells(runs: Sequence[Perturbation]) -> list[Outcome]:
        missing = sorted({r.test_id for r in runs} - set(scenarios))
        if missing:
            raise UserInputError(f"scenarios: no built scenario for tests {missing[:5]}")
        batch = [perturbed_scenario(scenarios[r.test_id], r) for r in runs]
        rows = summary_rows(simulate(batch, planner=make_planner(planner)))
        outcomes = []
        for row in rows:
            speed, rel = row["impact_ego_speed_mps"], row["impact_relative_longitudinal_speed_mps"]
            target = None if speed is None or rel is None else speed - rel
            outcomes.append(
                {
                    "collided": row["collided"],
                    "impact_speed_mps": speed,
                    "target_longitudinal_speed_mps": target,
                    "warning_ttc_s": row["warning_ttc_s"],
                }
            )
        return outcomes

    return simulate_cells
