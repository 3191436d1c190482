"""The preflight of a sweep: bounded for grids of many values, still naming a bad variant."""

from __future__ import annotations

import time
from pathlib import Path

import pytest
import yaml

from cli_helpers import assert_user_error, invoke
from conftest import PAPER_DIR
from vrusim.errors import UserInputError
from vrusim.sweep.design import make_design
from vrusim.sweep.plan import make_plan
from vrusim.sweep.preflight import preflight
from vrusim.sweep.spec import spec_from_mapping

BASE = {"base": str(PAPER_DIR / "pedestrian_crossing.yaml"), "set": {"sim.duration_s": 2.0}}


def plan_of(parameters: dict, samples: int = 1):
    return make_plan(spec_from_mapping({**BASE, "parameters": parameters, "samples": samples}, "s.yaml", Path(".")))


def test_a_grid_of_many_values_is_column_checked_not_built_value_by_value():
    plan = plan_of({"vrus[0].trigger.at_time_s": {"linspace": [0, 1, 50_000]}})
    started = time.perf_counter()
    found = preflight(plan, make_design(plan))
    assert time.perf_counter() - started < 1.0
    assert found.column_checked and found.checked < 300


def test_a_bad_value_inside_a_large_grid_still_names_its_variant():
    plan = plan_of({"vrus[0].top_speed_mps": {"linspace": [3.0, -1.0, 5001]}, "ego.cruise_speed_mps": [8.0, 9.0]})
    with pytest.raises(UserInputError, match=r"variant \d+ \(vrus\[0\]\.top_speed_mps=-"):
        preflight(plan, make_design(plan))


def test_a_small_grid_still_builds_every_value():
    plan = plan_of({"v2x.channel": ["ideal", "lossy", "bursty"]}, samples=400)
    assert preflight(plan, make_design(plan)).checked == 256 + 3  # first 256, the last, each channel's first


def test_dry_run_abridges_a_long_list_of_values(tmp_path):
    spec = tmp_path / "s.yaml"
    spec.write_text(yaml.safe_dump({**BASE, "parameters": {"vrus[0].trigger.at_time_s": {"linspace": [0, 1, 20_000]}}}))
    result = invoke("sweep", spec, "--dry-run")
    assert result.exit_code == 0, result.output
    assert "(20,000 values)" in result.stdout and len(result.stdout) < 1000


def test_dry_run_reports_a_bad_grid_value_as_a_user_error(tmp_path):
    spec = tmp_path / "s.yaml"
    spec.write_text(yaml.safe_dump({**BASE, "parameters": {"vrus[0].top_speed_mps": {"linspace": [3, -1, 3000]}}}))
    assert_user_error(invoke("sweep", spec, "--dry-run"), "variant", "vrus[0].top_speed_mps")


def test_a_planner_refusing_its_params_names_the_variant_and_its_values():
    plan = plan_of({"planner.name": ["fsm", "aeb"]}, samples=3)  # the base's params are the fsm planner's
    with pytest.raises(UserInputError) as caught:
        preflight(plan, make_design(plan))
    message = str(caught.value)
    assert message.startswith("variant 3 (planner.name='aeb'): ") and "planner.params.emergency_decel_mps2" in message
