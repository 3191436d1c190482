"""Shared fixtures: a minimal valid scenario mapping and the paper scenarios, to build tests from dicts."""

from __future__ import annotations

import copy
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from hypothesis import settings

from vrusim.scenario.loading import load_scenario, scenario_from_mapping
from vrusim.scenario.schema import Scenario

# Property tests draw their inputs from a fixed seed by default, so CI on a fresh clone (no example database)
# is reproducible; `HYPOTHESIS_PROFILE=explore python -m pytest` draws fresh random inputs to hunt for new cases.
settings.register_profile("ci", derandomize=True)
settings.register_profile("explore", derandomize=False)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))

# The suite's own test planners are named `module:Class` (tests.warning_planner:WarnOnDetection, ...): the suite
# allows module planners as a user would (vrusim --allow-module-planners); tests of the refusal unset it.
os.environ["VRUSIM_ALLOW_MODULE_PLANNERS"] = "1"

REPO_ROOT = Path(__file__).resolve().parents[1]
PAPER_DIR = REPO_ROOT / "scenarios" / "paper"
PAPER_FILES = sorted(PAPER_DIR.glob("*.yaml"))

FAR_VRU: dict[str, Any] = {
    "type": "pedestrian",
    "start": {"x_m": 500.0, "y_m": 50.0},
    "heading_deg": 90.0,
    "trigger": {"at_time_s": 1.0e6},
}
"""A VRU parked far off the ego's road that never starts moving (every scenario needs one VRU)."""


def minimal_scenario_dict() -> dict[str, Any]:
    """A fresh, valid, minimal scenario mapping: ego at the origin heading +x at 10 m/s, one far-away VRU."""
    return {
        "name": "test-minimal",
        "ego": {
            "start": {"x_m": 0.0, "y_m": 0.0, "heading_deg": 0.0},
            "cruise_speed_mps": 10.0,
            "route": {"kind": "straight", "length_m": 200.0},
            # explicit geometry (tests compute the rear axle and front bumper from these numbers)
            "length_m": 4.5,
            "width_m": 1.8,
            "wheelbase_m": 2.7,
            "rear_overhang_m": 0.9,
        },
        "planner": {"name": "none"},
        "vrus": [copy.deepcopy(FAR_VRU)],
        "sim": {"dt_s": 0.01, "duration_s": 5.0},
    }


def deep_update(base: dict[str, Any], changes: dict[str, Any]) -> dict[str, Any]:
    """Recursively merge `changes` into `base` (in place; lists and scalars are replaced) and return it."""
    for key, value in changes.items():
        if isinstance(value, dict) and isinstance(base.get(key), dict):
            deep_update(base[key], value)
        else:
            base[key] = copy.deepcopy(value)
    return base


@pytest.fixture
def scenario_dict() -> dict[str, Any]:
    """A fresh minimal valid scenario mapping that the test may modify freely."""
    return minimal_scenario_dict()


@pytest.fixture(scope="session")
def make_scenario() -> Callable[..., Scenario]:
    """Factory: `make_scenario(changes=None, base=None)` → validated Scenario (minimal mapping + changes).

    Session-scoped so that it can be used inside hypothesis tests.
    """

    def build(changes: dict[str, Any] | None = None, base: dict[str, Any] | None = None) -> Scenario:
        data = copy.deepcopy(base) if base is not None else minimal_scenario_dict()
        deep_update(data, changes or {})
        return scenario_from_mapping(data, "test")

    return build


@pytest.fixture(scope="session")
def paper_pedestrian_dict() -> dict[str, Any]:
    """The paper pedestrian-crossing scenario as a plain mapping (copy it before modifying)."""
    return load_scenario(PAPER_DIR / "pedestrian_crossing.yaml").model_dump(mode="json")


@pytest.fixture
def paper_pedestrian(paper_pedestrian_dict) -> dict[str, Any]:
    """A fresh copy of the paper pedestrian-crossing mapping that the test may modify."""
    return copy.deepcopy(paper_pedestrian_dict)
