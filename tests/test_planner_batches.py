"""The aeb and predictive planners act on whole batches: a variant's results do not depend on what else is in
its batch, and the threaded kernels give the serial kernels' results bit for bit."""

from __future__ import annotations

import copy

import numpy as np
import pytest

from vrusim import kernels
from vrusim.engine import accumulators as streaming
from vrusim.engine.accumulators import RunMetrics
from vrusim.engine.simulate import simulate
from vrusim.paper.cases import scenario_dir
from vrusim.scenario.loading import load_scenario, scenario_from_mapping

CASES = ("pedestrian_crossing.yaml", "escooter_leading.yaml", "motorcyclist_crossing.yaml")
SCRATCH = {"prev_actuator", "prev_clearance", "prev_speed"}
"""RunMetrics' step-to-step working state (still updated for a stopped variant while its batch runs on)."""


def results(metrics: RunMetrics, b: int) -> dict[str, np.ndarray]:
    """Every per-variant result array of RunMetrics for variant b (plain arrays and the packed rows by name)."""
    names = {name for name, value in vars(metrics).items() if isinstance(value, np.ndarray)} - {"values"}
    names |= set(streaming.FIELDS)
    return {name: np.asarray(getattr(metrics, name))[b] for name in sorted(names - SCRATCH) if name[0] != "_"}


def transitions(metrics: RunMetrics, b: int) -> list[tuple[float, int, int]]:
    return [(t, old, new) for t, index, old, new in metrics.transitions if index == b]


def variants(planner: str, count: int = 36) -> list:
    """Paper cases with varied speeds, triggers, V2X, a second VRU now and then, and varied planner params."""
    rng = np.random.default_rng(7)
    bases = [load_scenario(scenario_dir() / name).model_dump(mode="json") for name in CASES]
    out = []
    for i in range(count):
        data = copy.deepcopy(bases[i % len(bases)])
        data["name"] = f"{planner}-{i}"
        data["ego"]["cruise_speed_mps"] = round(float(data["ego"]["cruise_speed_mps"] * rng.uniform(0.8, 1.2)), 3)
        data["v2x"]["enabled"] = bool(i % 4 != 3)
        if planner == "predictive":
            params = {"time_margin_s": round(float(rng.uniform(0.3, 0.8)), 3)}
            if i % 3 == 1:
                params["prediction"] = "path"
        else:
            params = {"hysteresis_s": round(float(rng.uniform(0.2, 0.8)), 3)}
        data["planner"] = {"name": planner, "params": params}
        if i % 5 == 2:
            data["vrus"].append(
                {"type": "cyclist", "start": {"x_m": 15.0, "y_m": 9.0}, "heading_deg": -90.0, "top_speed_mps": 4.0,
                 "trigger": {"at_time_s": round(float(rng.uniform(0.5, 2.0)), 3)}}
            )  # fmt: skip
        out.append(scenario_from_mapping(data))
    return out


@pytest.mark.parametrize("planner", ["aeb", "predictive"])
def test_variant_alone_bitwise_equals_variant_in_batch(planner):
    batch = variants(planner)
    together = simulate(batch).metrics
    assert 0 < together.collided.sum() < len(batch)  # a mix of outcomes
    for b in (0, 4, 7, 13, len(batch) - 1):
        alone = simulate([batch[b]]).metrics
        mine, solo = results(together, b), results(alone, 0)
        assert mine.keys() == solo.keys()
        for name in mine:
            assert np.array_equal(mine[name], solo[name], equal_nan=True), f"{planner} variant {b}: {name}"
        assert transitions(together, b) == transitions(alone, 0)


@pytest.mark.parametrize("planner", ["aeb", "predictive"])
def test_threaded_kernels_match_serial(monkeypatch, planner):
    batch = variants(planner, count=12)
    serial = simulate(batch).metrics
    monkeypatch.setattr(kernels, "PARALLEL_MIN_BATCH", 1)
    threaded = simulate(batch).metrics
    for b in range(len(batch)):
        mine, other = results(serial, b), results(threaded, b)
        for name in mine:
            assert np.array_equal(mine[name], other[name], equal_nan=True), f"{planner} variant {b}: {name}"
    assert serial.transitions == threaded.transitions
