"""What a user names: one scenario YAML file, a bundled example, Euro NCAP catalogue tests, or a sweep spec.

A scenario SOURCE is
- a YAML file path, or an OpenSCENARIO file (`.xosc`, read by `vrusim.formats.xosc_import`);
- a bundled scenario by name: `paper:<case>` (pedestrian, escooter, motorcyclist) or `example:<name>`;
- a catalogue test id (`CPNA-25/20kph/day`), a code or prefix (`CPNA-25`, `CPNA`: its day tests, plus night with
  `night`) or `all`; looked up in the default Euro NCAP edition first, then the others; `2023:` or `2026:` in
  front names the edition (`2023:CPNA-25/20kph/day`).
A sweep SPEC is a YAML file or a bundled spec by name (`example:<name>`). `bundled()` lists every name; they
resolve inside an installed wheel too (`vrusim.io.bundled`). An unknown name is a user error that suggests close
names.
"""

from __future__ import annotations

import difflib
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from vrusim.errors import UserInputError
from vrusim.io.paths import check_name, os_reason, shown
from vrusim.scenario.schema import Scenario

if TYPE_CHECKING:
    from vrusim.ncap.build import NcapTest

YAML_SUFFIXES = (".yaml", ".yml")
SCENARIO_FILE_SUFFIXES = (*YAML_SUFFIXES, ".xosc")
"""Scenario files by suffix: YAML, and OpenSCENARIO XML (`vrusim.formats.xosc_import`)."""
PAPER_PREFIX = "paper:"
EXAMPLE_PREFIX = "example:"
BUNDLED_PREFIXES = (PAPER_PREFIX, EXAMPLE_PREFIX)

ScenarioSource = Scenario | str | Path
"""A Scenario; a YAML path; a bundled name (`paper:pedestrian`, `example:...`); or a catalogue test id."""


# ----------------------------------------------------------------------------------------------- bundled files


@dataclass(frozen=True)
class Bundled:
    """A scenario or sweep spec shipped with vrusim, reachable by name."""

    name: str
    """`paper:<case>` or `example:<name>`."""
    kind: str
    """"scenario" or "sweep"."""
    path: Path
    description: str


def _example_name(path: Path) -> str:
    return EXAMPLE_PREFIX + path.stem.replace("_", "-")


def _description(path: Path) -> str:
    from vrusim.scenario.yaml_file import read_yaml_file

    document = read_yaml_file(path, "bundled file")
    return str(document.get("description", "")) if isinstance(document, dict) else ""


def bundled_scenarios() -> list[Bundled]:
    """The bundled scenarios: the paper's cases (`paper:<case>`), then the examples (`example:<name>`)."""
    from vrusim.io.bundled import bundled_dir
    from vrusim.paper.cases import CASES, scenario_dir

    papers = [(PAPER_PREFIX + case.key, scenario_dir() / case.file_name) for case in CASES]
    examples = [(_example_name(p), p) for p in sorted((bundled_dir("scenarios") / "examples").glob("*.yaml"))]
    return [Bundled(name, "scenario", path, _description(path)) for name, path in papers + examples]


def bundled_sweeps() -> list[Bundled]:
    """The bundled sweep specs (`example:<name>`)."""
    from vrusim.io.bundled import bundled_dir

    specs = sorted(bundled_dir("sweeps").glob("*.yaml"))
    return [Bundled(_example_name(path), "sweep", path, _description(path)) for path in specs]


def bundled() -> list[Bundled]:
    """Every bundled scenario and sweep spec."""
    return bundled_scenarios() + bundled_sweeps()


def is_bundled_name(source: str) -> bool:
    """SOURCE has the form of a bundled name (`paper:...`, `example:...`)."""
    return source.startswith(BUNDLED_PREFIXES)


def _find(name: str, entries: list[Bundled], what: str, argument: str) -> Path:
    for entry in entries:
        if entry.name == name:
            return entry.path
    names = [entry.name for entry in entries]
    close = difflib.get_close_matches(name, names, n=3, cutoff=0.5)
    hint = f"did you mean {', '.join(close)}?" if close else f"expected one of {', '.join(names)}"
    raise UserInputError(f"{argument}: no bundled {what} named {name!r}; {hint} (`vrusim examples` lists them)")


def sweep_spec_path(source: str | Path, argument: str = "SPEC") -> Path:
    """The sweep spec file SOURCE names: a path, or a bundled spec by name (`example:pedestrian-monte-carlo`)."""
    text = str(source)
    if is_bundled_name(text):
        return _find(text, bundled_sweeps(), "sweep spec", argument)
    return Path(source)


# ----------------------------------------------------------------------------------------------- scenarios


def is_scenario_file(source: str) -> bool:
    """SOURCE names a file (a YAML suffix, or anything that exists); a folder is a user error."""
    path = check_name(source, "SOURCE")  # a null byte, a name too long for the OS
    try:
        if not (path.suffix.lower() in SCENARIO_FILE_SUFFIXES or path.exists()):
            return False
        folder = path.is_dir()
    except OSError as error:  # e.g. a folder on the way that cannot be read
        raise UserInputError(f"SOURCE: cannot use {shown(source)} as a file name ({os_reason(error)})") from None
    if folder:
        raise UserInputError(f"SOURCE: {source} is a folder, expected a scenario YAML file or a catalogue id")
    return True


def _editions_to_search(source: str) -> tuple[list[str], str]:
    """(edition names to look in, in order; SOURCE without its `EDITION:` prefix)."""
    from vrusim.ncap.editions import DEFAULT_EDITION, EDITION_NAMES

    prefix, colon, rest = source.strip().partition(":")
    if colon and prefix in EDITION_NAMES:
        return [prefix], rest.strip()
    return [DEFAULT_EDITION, *(name for name in EDITION_NAMES if name != DEFAULT_EDITION)], source.strip()


def catalogue_tests(source: str, night: bool) -> list[NcapTest]:
    """The catalogue tests SOURCE names in the first edition that has them (empty when none does)."""
    from vrusim.ncap.grid import select

    editions, wanted = _editions_to_search(source)
    for protocol in editions:
        try:
            if wanted.lower() == "all":
                return select(night=night, protocol=protocol)
            if "/" in wanted:
                code = wanted.split("/")[0]
                found = [t for t in select([code], True, protocol) if t.test_id.lower() == wanted.lower()]
            else:
                found = select([wanted], night=night, protocol=protocol)
        except UserInputError:  # an unknown code in this edition
            continue
        if found:
            return found
    return []


def unknown_source(source: str, expected: str, argument: str = "SOURCE") -> UserInputError:
    """The error for a SOURCE that names nothing: what was expected, and the closest names, catalogue ids or codes."""
    from vrusim.ncap.editions import EDITION_NAMES
    from vrusim.ncap.grid import select

    ids = [test.test_id for protocol in EDITION_NAMES for test in select(night=True, protocol=protocol)]
    codes = sorted({test_id.split("/")[0] for test_id in ids})
    names = [entry.name for entry in bundled_scenarios()]
    close = difflib.get_close_matches(source, [*names, *codes, *ids], n=5, cutoff=0.5)
    hint = f"; did you mean {', '.join(close)}?" if close else f"; catalogue codes: {', '.join(codes)}"
    return UserInputError(f"{argument}: {source!r} is not {expected}{hint}")


def load_scenario_file(path: Path) -> Scenario:
    """The scenario in a file: OpenSCENARIO XML by the suffix `.xosc`, else YAML."""
    if path.suffix.lower() == ".xosc":
        from vrusim.formats.xosc_import import read_scenario_file

        return read_scenario_file(path)
    from vrusim.scenario.loading import load_scenario

    return load_scenario(path)


def scenario_file(source: str, argument: str = "SOURCE") -> Path | None:
    """The YAML file SOURCE names (a path, or a bundled name: unknown is a user error), or None for a catalogue
    name."""
    if is_bundled_name(source):
        return _find(source, bundled_scenarios(), "scenario", argument)
    return Path(source) if is_scenario_file(source) else None


def resolve_source(source: str, night: bool) -> list[Scenario]:
    """The scenarios SOURCE names: one YAML file or bundled scenario, or catalogue tests (FSM planner, V2X off)."""
    from vrusim.ncap.build import build_test

    file = scenario_file(source, "SOURCE")
    if file is not None:
        return [load_scenario_file(file)]
    tests = catalogue_tests(source, night)
    if not tests:
        raise unknown_source(source, "a scenario file, a bundled name, a catalogue test id, code or prefix, or 'all'")
    return [build_test(test).scenario for test in tests]


def single_test(
    source: str, expected: str = "a scenario file, a bundled name or a catalogue test id", argument: str = "SOURCE"
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
    """The one scenario SOURCE names: a YAML file or bundled scenario (V2X as in it), or one catalogue test id (FSM
    planner; with `catalogue_v2x` the catalogue's roadside unit, switched on)."""
    from vrusim.ncap.build import build_test

    file = scenario_file(source, "SOURCE")
    if file is not None:
        return load_scenario_file(file)
    return build_test(single_test(source), v2x=catalogue_v2x).scenario


def scenario_of(
    source: ScenarioSource, v2x: bool | None = None, argument: str = "SOURCE", option: str = "v2x"
) -> Scenario:
    """The one scenario `source` names, with V2X switched on or off when `v2x` is given (None: as it is; a catalogue
    test: off). A Scenario is taken as it is; a catalogue test is built for the FSM planner, with its roadside unit
    switched on by `v2x`. Errors name `argument` (the source) or `option` (the V2X switch)."""
    if isinstance(source, Scenario):
        return apply_v2x_switch(source, v2x, option)
    if not isinstance(source, str | Path):
        raise UserInputError(
            f"{argument}: expected a Scenario, a YAML path, a bundled name or a catalogue test id, got {source!r}"
        )
    text = str(source)
    if isinstance(source, Path) or is_bundled_name(text) or is_scenario_file(text):
        file = Path(source) if isinstance(source, Path) else scenario_file(text, argument)
        return apply_v2x_switch(load_scenario_file(file), v2x, option, str(file))
    from vrusim.ncap.build import build_test

    expected = "a YAML file, a bundled name (`paper:<case>`, `example:<name>`) or a catalogue test id"
    return build_test(single_test(text, expected, argument), v2x=bool(v2x)).scenario


# ----------------------------------------------------------------------------------------------- choices


def apply_v2x_switch(
    scenario: Scenario, enabled: bool | None, option: str = "v2x", source: str | None = None
) -> Scenario:
    """`scenario` with V2X switched on or off (None: unchanged), validated again. A scenario that cannot take it
    (V2X on without a roadside unit) is a UserInputError that names `source` (default: the scenario's name), the
    `option` and each offending field."""
    if enabled is None:
        return scenario
    from vrusim.scenario.field_paths import replaced

    where = f"{source or scenario.name} with {option} {'on' if enabled else 'off'}"
    return replaced(scenario, {"v2x.enabled": bool(enabled)}, where)


def apply_planner_and_seed(scenario: Scenario, planner: str | None = None, seed: int | None = None) -> Scenario:
    """`scenario` driven by `planner` (its parameters kept only when it is the scenario's own planner) and keyed by
    `seed` (None: unchanged), validated again (`vrusim.scenario.settings.with_settings`)."""
    from vrusim.scenario.settings import with_settings

    return with_settings(scenario, planner=planner, seed=seed)
