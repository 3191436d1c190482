"""What a SOURCE argument names: one scenario YAML file, or Euro NCAP catalogue tests.

A catalogue SOURCE is a test id (`CPNA-25/20kph/day`), a code or prefix (`CPNA-25`, `CPNA`: its day tests, plus
night with `night`) or `all`. An unknown name is a user error that suggests close ids.
"""

from __future__ import annotations

import difflib
from pathlib import Path
from typing import TYPE_CHECKING

from vrusim.errors import UserInputError

if TYPE_CHECKING:
    from vrusim.ncap.build import NcapTest
    from vrusim.scenario.schema import Scenario

YAML_SUFFIXES = (".yaml", ".yml")


def is_scenario_file(source: str) -> bool:
    """SOURCE names a file (a YAML suffix, or anything that exists); a folder is a user error."""
    path = Path(source)
    if not (path.suffix.lower() in YAML_SUFFIXES or path.exists()):
        return False
    if path.is_dir():
        raise UserInputError(f"SOURCE: {source} is a folder, expected a scenario YAML file or a catalogue id")
    return True


def catalogue_tests(source: str, night: bool) -> list[NcapTest]:
    """The catalogue tests SOURCE names (empty when it names none)."""
    from vrusim.ncap.grid import select

    wanted = source.strip()
    try:
        if wanted.lower() == "all":
            return select(night=night)
        if "/" in wanted:
            return [t for t in select([wanted.split("/")[0]], night=True) if t.test_id.lower() == wanted.lower()]
        return select([wanted], night=night)
    except UserInputError:  # an unknown code
        return []


def unknown_source(source: str, expected: str, argument: str = "SOURCE") -> UserInputError:
    """The error for a SOURCE that names nothing: what was expected, and the closest catalogue ids or codes."""
    from vrusim.ncap.grid import select

    ids = [test.test_id for test in select(night=True)]
    codes = sorted({test_id.split("/")[0] for test_id in ids})
    close = difflib.get_close_matches(source, [*codes, *ids], n=5, cutoff=0.5)
    hint = f"; did you mean {', '.join(close)}?" if close else f"; catalogue codes: {', '.join(codes)}"
    return UserInputError(f"{argument}: {source!r} is not {expected}{hint}")


def resolve_source(source: str, night: bool) -> list[Scenario]:
    """The scenarios SOURCE names: one YAML file, or catalogue tests (FSM planner, V2X off)."""
    from vrusim.ncap.build import build_test
    from vrusim.scenario.loading import load_scenario

    if is_scenario_file(source):
        return [load_scenario(Path(source))]
    tests = catalogue_tests(source, night)
    if not tests:
        raise unknown_source(source, "a scenario file, a catalogue test id, code or prefix, or 'all'")
    return [build_test(test).scenario for test in tests]


def single_test(
    source: str, expected: str = "a scenario file or a catalogue test id", argument: str = "SOURCE"
) -> NcapTest:
    """The one catalogue test SOURCE names (day or night); none, or a code that selects several, is a user error
    naming `argument`."""
    tests = catalogue_tests(source, night=True)
    if not tests:
        raise unknown_source(source, expected, argument)
    if len(tests) > 1:
        raise UserInputError(
            f"{argument}: {source!r} selects {len(tests)} catalogue tests; give one test id, e.g. {tests[0].test_id} "
            f"(`vrusim ncap --scenario {source}` runs them all)"
        )
    return tests[0]


def single_source(source: str, catalogue_v2x: bool) -> Scenario:
    """The one scenario SOURCE names: a YAML file, or one catalogue test id (FSM planner; with `catalogue_v2x`
    the catalogue's roadside unit, switched on)."""
    from vrusim.ncap.build import build_test
    from vrusim.scenario.loading import load_scenario

    if is_scenario_file(source):
        return load_scenario(Path(source))
    return build_test(single_test(source), v2x=catalogue_v2x).scenario
