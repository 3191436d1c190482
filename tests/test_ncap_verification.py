"""The verification Monte Carlo: sampler counts (FC26 §4.2.1), pass rule, scaling (§5.3.4), seeds, speed."""

from __future__ import annotations

import numpy as np
import pytest

from vrusim.errors import UserInputError
from vrusim.ncap.grid import run_tests, select
from vrusim.ncap.rating2026 import assess_2026
from vrusim.ncap.rating2026 import tables as t
from vrusim.ncap.rating2026.colours import KPH
from vrusim.ncap.verification import (
    Perturbation,
    judge,
    monte_carlo,
    perturbations,
    perturbed_scenario,
    sample_lab,
    vrusim_simulator,
)


def grid_rows(colour_at):
    """CPNA day 10..60 km/h × five impact locations; standard 75/50/25 %, extended 90/10 %."""
    rows = []
    for vut in (10, 20, 30, 40, 50, 60):
        for loc in (0.9, 0.75, 0.5, 0.25, 0.1):
            vrel = colour_at(vut, loc)
            rows.append({
                "test_id": f"{vut}-{loc}", "protocol": "2026", "scenario": "CPNA", "official_scenario": "CPNA day",
                "vut_speed_kph": vut, "impact_location": loc, "target_speed_kph": 5.0,
                "range": "standard" if loc in (0.75, 0.5, 0.25) else "extended", "function": "AEB",
                "collided": vrel is not None, "impact_speed_mps": None if vrel is None else vrel * KPH,
                "target_longitudinal_speed_mps": 0.0, "warning_ttc_s": None, "planner_warns": False,
            })  # fmt: skip
    return rows


def nominal(assessment):
    rows = {c.test_id: c for c in assessment.cells}

    def simulate(runs):
        out = []
        for run in runs:
            kpi = rows[run.test_id].kpi
            out.append(
                {"collided": bool(kpi), "impact_speed_mps": (kpi or 0) * KPH, "target_longitudinal_speed_mps": 0}
            )
        return out

    return simulate


def test_lab_sample_counts_follow_fc26_table():
    a = assess_2026(grid_rows(lambda vut, loc: 40.0 if vut == 10 and loc == 0.5 else None))
    for seed in range(20):
        sample = sample_lab(a, np.random.default_rng(seed))["CPNA day"]
        assert len(sample["standard"]) == t.STANDARD_VERIFICATION_TESTS["CPNA day"] == 3
        assert len(sample["extended"]) == 2
        assert all(c.colour != "red" for c in sample["standard"])
        assert len({c.test_id for c in sample["standard"]}) == 3


def test_perturbations_stay_within_tolerances():
    a = assess_2026(grid_rows(lambda vut, loc: None))
    runs = perturbations(a.cells, 50, np.random.default_rng(0))
    dv = np.array([r.vut_speed_delta_kph for r in runs])
    dy = np.array([r.lateral_offset_m for r in runs])
    dt = np.array([r.target_timing_s for r in runs])
    assert dv.min() >= 0 and dv.max() <= 1.0 and np.abs(dy).max() <= 0.05 and np.abs(dt).max() <= 0.1


def test_judge_uses_the_2_kph_tolerance():
    cell = assess_2026(grid_rows(lambda vut, loc: 5.0 if vut == 60 else None)).cells_of("CPNA day")[-4]
    assert cell.colour == "yellow" and cell.vut_speed_kph == 60
    assert judge(cell, {"collided": True, "impact_speed_mps": 11.9 * KPH})[0]
    assert not judge(cell, {"collided": True, "impact_speed_mps": 12.1 * KPH})[0]
    assert judge(cell, {"collided": False, "impact_speed_mps": None}) == (True, "green")


def test_exact_predictions_keep_their_points_and_failures_scale_them():
    a = assess_2026(grid_rows(lambda vut, loc: None))
    exact = monte_carlo(a, nominal(a), n_draws=200, n_perturbations=4, seed=1)
    assert exact.scenarios["CPNA day"].mean == pytest.approx(a.scenarios["CPNA day"].total)
    assert exact.scenarios["CPNA day"].std == 0.0 and set(exact.pass_probability.values()) == {1.0}

    def crash(runs):
        return [{"collided": True, "impact_speed_mps": 50 * KPH, "target_longitudinal_speed_mps": 0}] * len(runs)

    failed = monte_carlo(a, crash, n_draws=50, n_perturbations=2, seed=1)
    assert failed.scenarios["CPNA day"].mean == 0.0  # 0 of 3 and 0 of 2 passed: 0 % (FC26 §5.3.4)
    self_claimed = monte_carlo(a, crash, n_draws=10, n_perturbations=2, method="Self claimed")
    assert self_claimed.scenarios["CPNA day"].p95 == 0.0


def test_one_failure_in_three_gives_67_percent():
    a = assess_2026(grid_rows(lambda vut, loc: None))
    bad = {"60-0.5"}

    def simulate(runs):
        return [{"collided": r.test_id in bad, "impact_speed_mps": 50 * KPH} for r in runs]

    report = monte_carlo(a, simulate, n_draws=4000, n_perturbations=1, seed=3)
    p_pick = 3 / 18  # the bad cell is among the 3 of 18 standard cells
    expected = 0.5 * (1 - p_pick) + 0.5 * 0.67 * p_pick + 0.0625
    assert report.scenarios["CPNA day"].mean == pytest.approx(expected, abs=0.01)
    assert report.pass_probability["60-0.5"] == 0.0


def test_seeds_are_reproducible():
    a = assess_2026(grid_rows(lambda vut, loc: 15.0 if vut >= 40 else None))

    def noisy(runs):
        return [{"collided": True, "impact_speed_mps": (14 + 4 * r.vut_speed_delta_kph) * KPH} for r in runs]

    one = monte_carlo(a, noisy, n_draws=300, n_perturbations=8, seed=5).to_dict()
    two = monte_carlo(a, noisy, n_draws=300, n_perturbations=8, seed=5).to_dict()
    other = monte_carlo(a, noisy, n_draws=300, n_perturbations=8, seed=6).to_dict()
    assert one == two and one != other
    with pytest.raises(UserInputError, match="n_draws"):
        monte_carlo(a, noisy, n_draws=0)


def test_vrusim_simulator_perturbs_and_runs_one_batch():
    """The real 2026 CPNA and CBNA grids: unperturbed runs reproduce the grid's outcomes; the Monte Carlo covers
    both scenarios (its speed is measured in benchmarks/bench_verification.py, not here)."""
    tests = [t for t in select(["CPNA", "CBNA"], protocol="2026") if t.spec.code in ("CPNA", "CBNA")]
    run = run_tests(tests)
    a = assess_2026(run.rows)
    scenarios = {b.test.test_id: b.scenario for b in run.built}
    first = run.built[0].scenario
    moved = perturbed_scenario(first, Perturbation(run.built[0].test.test_id, 1.0, 0.05, 0.1))
    assert moved.ego.cruise_speed_mps == pytest.approx(first.ego.cruise_speed_mps + KPH)
    assert moved.ego.start.y_m == pytest.approx(first.ego.start.y_m + 0.05)
    simulate = vrusim_simulator(scenarios)
    same = simulate([Perturbation(r["test_id"], 0.0, 0.0, 0.0) for r in run.rows])
    assert [o["collided"] for o in same] == [r["collided"] for r in run.rows]
    report = monte_carlo(a, simulate, n_draws=200, n_perturbations=4, seed=0)
    assert report.n_draws == 200 and set(report.scenarios) == {"CPNA day", "CBNA"}
    assert all(0.0 <= p <= 1.0 for p in report.pass_probability.values())
