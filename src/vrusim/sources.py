"""What a SOURCE argument names: a scenario YAML file, a bundled scenario, or Euro NCAP catalogue tests.

A bundled scenario is named `paper:<case>` (the paper's case studies: pedestrian, escooter, motorcyclist) or
`example:<name>` (the files under scenarios/examples, `_` written `-`: `example:right-turn-cyclist`); bundled
sweep specs are named `example:<name>` too (sweeps/*.yaml). A catalogue SOURCE is a test id
(`CPNA-25/20kph/day`), a code or prefix (`CPNA-25`, `CPNA`: its day tests, plus night with `night`) or `all`.
An unknown name is a user error that lists the bundled names or suggests close catalogue ids.
"""

from __future__ import annotations

import difflib
from collections.abc import Callable
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING, Union

from vrusim.errors import UserInputError

if TYPE_CHECKING:
    from vrusim.ncap.build import NcapTest
    from vrusim.scenario.schema import Scenario

YAML_SUFFIXES = (".yaml", ".yml")
PAPER_PREFIX = "paper:"
EXAMPLE_PREFIX = "example:"
BUNDLED_PREFIXES = (PAPER_PREFIX, EXAMPLE_PREFIX)


def _example_files(folder: Path) -> dict[str, Path]:
    """`example:<stem with - for _>` → file, for the YAML files of `folder` (none when it is missing)."""
    if not folder.is_dir():
        return {}
    files = sorted(p for p in folder.iterdir() if p.suffix.lower() in YAML_SUFFIXES)
    return {EXAMPLE_PREFIX + p.stem.replace("_", "-"): p for p in files}


def bundled_scenarios() -> dict[str, Path]:
    """Every bundled scenario file by name: the paper's cases (`paper:pedestrian`, ...), then the examples."""
    from vrusim.paper.cases import CASES, scenario_dir

    paper = scenario_dir()
    names = {PAPER_PREFIX + case.key: paper / case.file_name for case in CASES}
    return names | _example_files(paper.parent / "examples")


def bundled_sweep_specs() -> dict[str, Path]:
    """Every bundled sweep spec file by name (`example:pedestrian-monte-carlo`): the installed package's
    `_sweeps` folder, else the source checkout's `sweeps`."""
    packaged = resources.files("vrusim") / "_sweeps"
    if packaged.is_dir():
        return _example_files(Path(str(packaged)))
    return _example_files(Path(__file__).resolve().parents[2] / "sweeps")


def bundled_file(
    source: str, bundled: Callable[[], dict[str, Path]], what: str, argument: str = "SOURCE"
) -> Path | None:
    """The file a bundled name stands for (`bundled()` lists them); None when `source` is not written as one (no
    `paper:` or `example:` prefix); an unknown name with such a prefix is a user error listing the names."""
    if not source.startswith(BUNDLED_PREFIXES):
        return None
    names = bundled()
    if source in names:
        return names[source]
    close = difflib.get_close_matches(source, list(names), n=1)
    hint = f" (did you mean {close[0]}?)" if close else ""
    raise UserInputError(f"{argument}: unknown bundled {what} {source!r}{hint}; expected one of: {', '.join(names)}")


def scenario_file(source: str, argument: str = "SOURCE") -> Path | None:
    """The scenario file SOURCE names: a bundled scenario, or a path (a YAML suffix, or anything that exists);
    None when it names no file. A folder is a user error."""
    bundled = bundled_file(source, bundled_scenarios, "scenario", argument)
    if bundled is not None:
        return bundled
    path = Path(source)
    if not (path.suffix.lower() in YAML_SUFFIXES or path.exists()):
        return None
    if path.is_dir():
        raise UserInputError(f"{argument}: {source} is a folder, expected a scenario YAML file or a catalogue id")
    return path


def is_scenario_file(source: str) -> bool:
    """SOURCE names a scenario file (a bundled scenario, a YAML suffix, or anything that exists); a folder is a
    user error."""
    return scenario_file(source) is not None


def sweep_spec_file(source: str | Path, argument: str = "SPEC") -> Path:
    """The sweep spec file SOURCE names: a bundled spec (`example:pedestrian-monte-carlo`) or a path."""
    bundled = bundled_file(str(source), bundled_sweep_specs, "sweep spec", argument)
    return Path(source) if bundled is None else bundled


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
    """The scenarios SOURCE names: one YAML file or bundled scenario, or catalogue tests (FSM planner, V2X off)."""
    from vrusim.ncap.build import build_test
    from vrusim.scenario.loading import load_scenario

    file = scenario_file(source)
    if file is not None:
        return [load_scenario(file)]
    tests = catalogue_tests(source, night)
    if not tests:
        raise unknown_source(
            source, "a scenario file, a bundled scenario, a catalogue test id, code or prefix, or 'all'"
        )
    return [build_test(test).scenario for test in tests]


ONE_SCENARIO = "a scenario file, a bundled scenario (paper:<case>, example:<name>) or a catalogue test id"
"""What a SOURCE that names one scenario may be (for error messages)."""


def single_test(source: str, expected: str = ONE_SCENARIO, argument: str = "SOURCE") -> NcapTest:
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


def single_source(source: str, catalogue_v2x: bool, argument: str = "SOURCE") -> Scenario:
    """The one scenario SOURCE names: a YAML file, a bundled scenario, or one catalogue test id (FSM planner; with
    `catalogue_v2x` the catalogue's roadside unit, switched on). A bad SOURCE is a user error naming `argument`."""
    from vrusim.ncap.build import build_test
    from vrusim.scenario.loading import load_scenario

    file = scenario_file(source, argument)
    if file is not None:
        return load_scenario(file)
    return build_test(single_test(source, argument=argument), v2x=catalogue_v2x).scenario


ScenarioSource = Union["Scenario", str, Path]
"""What `load_source` takes: a Scenario; a YAML path; a bundled name (`paper:pedestrian`); a catalogue test id."""


def load_source(source: Scenario | str | Path, argument: str = "scenario") -> Scenario:
    """The Scenario `source` names: a Scenario (as it is), a YAML file (a `Path` is always read as one), a bundled
    scenario or one catalogue test id (FSM planner, V2X off, its roadside unit placed). A bad source is a user
    error naming `argument`."""
    from vrusim.scenario.loading import load_scenario
    from vrusim.scenario.schema import Scenario

    if isinstance(source, Scenario):
        return source
    if isinstance(source, Path):
        return load_scenario(source)
    if not isinstance(source, str):
        expected = "a Scenario, a YAML path, a bundled name or a catalogue test id"
        raise UserInputError(f"{argument}: expected {expected}, got {source!r}")
    return single_source(source, catalogue_v2x=False, argument=argument)
