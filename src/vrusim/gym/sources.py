"""Turn what a user names — a Scenario, a YAML file, a paper case or a catalogue test id — into a Scenario."""

from __future__ import annotations

from pathlib import Path

from vrusim.errors import UserInputError
from vrusim.scenario.schema import Scenario

ScenarioSource = Scenario | str | Path
"""A Scenario; a YAML path; `paper:<case>` (pedestrian, escooter, motorcyclist); or a catalogue test id."""

PAPER_PREFIX = "paper:"


def resolve_scenario(source: ScenarioSource, v2x: bool | None = None) -> Scenario:
    """The Scenario behind `source`; `v2x` (when given) switches its V2X on or off."""
    scenario = _resolve(source)
    return scenario if v2x is None else scenario.with_v2x(bool(v2x))


def _resolve(source: ScenarioSource) -> Scenario:
    if isinstance(source, Scenario):
        return source
    if not isinstance(source, str | Path):
        raise UserInputError(f"scenario: expected a Scenario, a YAML path or a catalogue test id, got {source!r}")
    text = str(source)
    if text.startswith(PAPER_PREFIX):
        return _paper(text[len(PAPER_PREFIX) :])
    if isinstance(source, Path) or text.endswith((".yaml", ".yml")) or Path(text).is_file():
        from vrusim.scenario.loading import load_scenario

        return load_scenario(Path(text))
    return _catalogue(text)


def _paper(key: str) -> Scenario:
    from vrusim.paper.cases import CASES, scenario_dir
    from vrusim.scenario.loading import load_scenario

    for case in CASES:
        if case.key == key:
            return load_scenario(scenario_dir() / case.file_name)
    raise UserInputError(f"scenario: unknown paper case {key!r}; expected one of {[c.key for c in CASES]}")


def _catalogue(test_id: str) -> Scenario:
    """A Euro NCAP catalogue test by its full id, e.g. `CPNA-25/20kph/day` (built for the fsm planner)."""
    from vrusim.ncap.build import build_test
    from vrusim.sources import single_test

    expected = "a YAML file, `paper:<case>` or a catalogue test id"
    return build_test(single_test(test_id, expected, argument="scenario")).scenario
