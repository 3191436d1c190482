"""What a SOURCE argument names: one scenario YAML file, or Euro NCAP catalogue tests.

A catalogue SOURCE is a test id (`CPNA-25/20kph/day`), a code or prefix (`CPNA-25`, `CPNA`: its day tests, plus
night with `night`) or `all`. An unknown name is a user error that suggests close ids.
"""

from __future__ import annotations

import difflib
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from vrusim.errors import UserInputError

if TYPE_CHECKING:
    from vrusim.catalog.ncap_build import NcapTest
    from vrusim.scenario.schema import Scenario

YAML_SUFFIXES = (".yaml", ".yml")

OneSource = Annotated[
    str,
    typer.Argument(
        metavar="FILE.yaml|TEST-ID",
        help="Scenario YAML file, or one Euro NCAP catalogue test id (`vrusim list`), e.g. CPNA-25/20kph/day.",
        show_default=False,
    ),
]
"""The SOURCE argument of commands that take one scenario (`single_source`)."""


def is_scenario_file(source: str) -> bool:
    """SOURCE names a file (a YAML suffix, or anything that exists); a folder is a user error."""
    path = Path(source)
    if not (path.suffix.lower() in YAML_SUFFIXES or path.exists()):
        return False
    if path.is_dir():
        raise UserInputError(f"SOURCE: {source} is a folder, expected a scenario YAML file or a catalogue id")
    return True


def catalogue_tests(source: str, night: bool) -> list[NcapTest]:
    """The catalogue tests SOURCE names; none is a user error with close ids as a hint."""
    from vrusim.catalog.ncap import select

    wanted = source.strip()
    try:
        if wanted.lower() == "all":
            tests = select(night=night)
        elif "/" in wanted:
            tests = [t for t in select([wanted.split("/")[0]], night=True) if t.test_id.lower() == wanted.lower()]
        else:
            tests = select([wanted], night=night)
    except UserInputError:  # an unknown code: answered below with close ids
        tests = []
    if tests:
        return list(tests)
    ids = [test.test_id for test in select(night=True)]
    codes = sorted({test_id.split("/")[0] for test_id in ids})
    close = difflib.get_close_matches(source, [*codes, *ids], n=5, cutoff=0.5)
    hint = f"; did you mean {', '.join(close)}?" if close else f"; catalogue codes: {', '.join(codes)}"
    raise UserInputError(f"SOURCE: {source!r} is neither a scenario file nor a catalogue test id, code or 'all'{hint}")


def resolve_source(source: str, night: bool) -> list[Scenario]:
    """The scenarios SOURCE names: one YAML file, or catalogue tests (FSM planner, V2X off)."""
    from vrusim.catalog.ncap_build import build_test
    from vrusim.scenario.loading import load_scenario

    if is_scenario_file(source):
        return [load_scenario(Path(source))]
    return [build_test(test).scenario for test in catalogue_tests(source, night)]


def single_source(source: str, catalogue_v2x: bool) -> Scenario:
    """The one scenario SOURCE names: a YAML file, or one catalogue test id (FSM planner; with `catalogue_v2x`
    the catalogue's roadside unit, switched on). A code that selects several tests is a user error."""
    from vrusim.catalog.ncap_build import build_test
    from vrusim.scenario.loading import load_scenario

    if is_scenario_file(source):
        return load_scenario(Path(source))
    tests = catalogue_tests(source, night=True)
    if len(tests) > 1:
        raise UserInputError(
            f"SOURCE: {source!r} selects {len(tests)} catalogue tests; give one test id, e.g. {tests[0].test_id} "
            f"(`vrusim ncap --scenario {source}` runs them all)"
        )
    return build_test(tests[0], v2x=catalogue_v2x).scenario
