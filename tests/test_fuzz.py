"""Fuzz test (issue 18): malformed scenario files (YAML and OpenSCENARIO), scenarios with extreme values inside the
physical bounds, sweep specs and command lines get a result or one clear error (exit 2 with a message), never a
traceback, and results never hold NaN or infinity.

A fixed number of examples per run keeps the CI time bounded (about 11 s); `scripts/fuzz_campaign.py` runs the
same generators thousands of times outside CI and measures hangs and memory too.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

from hypothesis import HealthCheck, given, settings

from fuzz_inputs import (
    cli_arguments,
    finite_results,
    invoke_cli,
    physics_texts,
    scenario_texts,
    sweep_texts,
    with_folder,
    write_input,
    xosc_texts,
)


def fuzz(examples: int) -> settings:
    """Settings of a fuzz test: `examples` derandomized examples (the same on every CI run: a failure is
    reproducible), no deadline, no example database."""
    return settings(
        max_examples=examples,
        deadline=None,
        database=None,
        derandomize=True,
        suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large, HealthCheck.filter_too_much],
    )


def _answer(args: list[str], text: str | None = None, suffix: str = ".yaml") -> None:
    """Run `vrusim ARGS` (with `text` written to the file `FILE` stands for) in a fresh folder and check the
    answer."""
    with tempfile.TemporaryDirectory() as folder:
        if text is not None:
            path = write_input(Path(folder), text, suffix)
            args = [str(path) if arg == "FILE" else arg for arg in args]
        verdict = invoke_cli(with_folder(args, folder))
    assert verdict.acceptable, (args[:1], verdict.exit_code, verdict.output[-2000:], verdict.traceback)
    if verdict.exit_code == 0:
        assert finite_results(verdict.output), verdict.output[-2000:]


@fuzz(80)
@given(text=scenario_texts())
def test_malformed_scenario_files_get_a_result_or_one_clear_error(text):
    _answer(["run", "FILE", "--json"], text)


@fuzz(40)
@given(text=physics_texts())
def test_extreme_but_bounded_physics_runs_with_finite_results_or_one_clear_error(text):
    _answer(["run", "FILE", "--json"], text)


@fuzz(40)
@given(text=xosc_texts())
def test_malformed_openscenario_files_get_a_result_or_one_clear_error(text):
    _answer(["run", "FILE", "--json"], text, ".xosc")


@fuzz(60)
@given(text=sweep_texts())
def test_malformed_sweep_specs_get_a_plan_or_one_clear_error(text):
    _answer(["sweep", "FILE", "--dry-run", "--json"], text)


@fuzz(60)
@given(args=cli_arguments())
def test_hostile_command_lines_get_a_result_or_one_clear_error(args):
    _answer(args)
