"""Turn what a user names — a Scenario, a YAML file, a bundled scenario or a catalogue test id — into a Scenario."""

from __future__ import annotations

from vrusim.scenario.schema import Scenario
from vrusim.sources import ScenarioSource, load_source

__all__ = ["ScenarioSource", "resolve_scenario"]


def resolve_scenario(source: ScenarioSource, v2x: bool | None = None) -> Scenario:
    """The Scenario behind `source` (`vrusim.sources.load_source`); `v2x` (when given) switches its V2X on or off."""
    scenario = load_source(source, "scenario")
    return scenario if v2x is None else scenario.with_v2x(bool(v2x))
