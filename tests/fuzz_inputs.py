"""Hypothesis strategies of hostile input for vrusim (issue 18): malformed scenario documents, sweep specs and CLI
argument lists, and the check that vrusim answers each with a result or one clear error.

Used by `tests/test_fuzz.py` (a fixed number of examples in CI) and `scripts/fuzz_campaign.py` (thousands, outside
CI). Every input is built from a valid bundled file: mutations keep most of it intact, so the fuzzer reaches the
checks behind the first one.
"""

from __future__ import annotations

import copy
import functools
import math
import re
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml
from hypothesis import strategies as st

ROOT = Path(__file__).resolve().parents[1]
BASE_SCENARIO = ROOT / "scenarios" / "paper" / "pedestrian_crossing.yaml"
BASE_SWEEP = ROOT / "sweeps" / "pedestrian_monte_carlo.yaml"
SHORT_RUN_S = 2.0
"""Duration given to the base scenario, s: a mutated document that is still valid runs quickly."""
SWEEP_SAMPLES = 4
"""Samples of the base sweep spec (only planned and checked: `--dry-run`)."""

SPECIAL_STRINGS = (
    "",
    "\0",
    "nan",
    "-inf",
    "1e308",
    "1e-320",
    "0x10",
    "module:Class",
    "os:system",
    "../../../../etc/passwd",
    "/dev/zero",
    "x" * 300,
    "a/" * 2100,
    "ü\u202e\ufeff",
    "{{ 7 * 7 }}",
    "!!python/object/apply:os.system ['true']",
)
SPECIAL_NUMBERS = (0, -1, 1, 2**31, 2**63, 2**64, 10**30, 10**400, 1e308, -1e308, 5e-324, 1e15, 1e6, -0.0)


def scalars() -> st.SearchStrategy:
    """Leaf values: ordinary and extreme numbers, NaN and infinities, strings that mean something elsewhere."""
    return st.one_of(
        st.none(),
        st.booleans(),
        st.integers(min_value=-(2**70), max_value=2**70),
        st.sampled_from(SPECIAL_NUMBERS),
        st.floats(allow_nan=True, allow_infinity=True),
        st.text(max_size=12),
        st.sampled_from(SPECIAL_STRINGS),
    )


def junk() -> st.SearchStrategy:
    """Any YAML-representable value: scalars nested in lists and mappings."""
    return st.recursive(
        scalars(),
        lambda children: st.lists(children, max_size=4) | st.dictionaries(st.text(max_size=8), children, max_size=4),
        max_leaves=10,
    )


def _paths(value: Any, prefix: tuple = ()) -> list[tuple]:
    """Every path (keys and indices) to a value inside nested mappings and lists, the root excluded."""
    out = []
    items = value.items() if isinstance(value, dict) else enumerate(value) if isinstance(value, list) else ()
    for key, child in items:
        out.append((*prefix, key))
        out += _paths(child, (*prefix, key))
    return out


def _parent(document: Any, path: tuple) -> Any:
    for key in path[:-1]:
        document = document[key]
    return document


def _nested(depth: int, mapping: bool) -> Any:
    value: Any = 1
    for _ in range(depth):
        value = {"a": value} if mapping else [value]
    return value


@st.composite
def mutated(draw: st.DrawFn, base: dict) -> dict:
    """`base` with one to three mutations: a value replaced by junk or deep nesting, a key removed, an unknown
    key added, a list emptied or repeated."""
    document = copy.deepcopy(base)
    for _ in range(draw(st.integers(1, 3))):
        paths = _paths(document)
        if not paths:
            break
        path = draw(st.sampled_from(paths))
        parent = _parent(document, path)
        kind = draw(st.sampled_from(("replace", "replace", "replace", "delete", "add", "deep", "grow")))
        if kind == "replace":
            parent[path[-1]] = draw(junk())
        elif kind == "delete":
            del parent[path[-1]]
        elif kind == "add" and isinstance(parent, dict):
            parent[draw(st.text(min_size=1, max_size=10))] = draw(junk())
        elif kind == "deep":
            parent[path[-1]] = _nested(draw(st.sampled_from((20, 40, 600))), draw(st.booleans()))
        elif kind == "grow" and isinstance(parent[path[-1]], list):
            parent[path[-1]] = parent[path[-1]] * draw(st.sampled_from((0, 2, 50)))
    return document


def dump(document: Any) -> str:
    """YAML text of a document (Python objects YAML cannot represent as text are written with `repr`)."""
    try:
        return yaml.safe_dump(document, allow_unicode=True, sort_keys=False, width=10**6)
    except (yaml.YAMLError, RecursionError, ValueError):
        return repr(document)


@st.composite
def corrupted_text(draw: st.DrawFn, text: str) -> str:
    """YAML text cut short, with a character inserted, or with a line repeated."""
    kind = draw(st.sampled_from(("cut", "insert", "repeat", "as_is", "as_is")))
    if kind == "as_is" or not text:
        return text
    at = draw(st.integers(len(text) // 4, len(text) - 1))  # keep the start: the checks behind the first
    if kind == "cut":
        return text[:at]
    if kind == "insert":
        return text[:at] + draw(st.sampled_from(("\t", ":", "- ", "&a ", "*a", "{", "]", "!!", "%", "\0"))) + text[at:]
    lines = text.splitlines(keepends=True)
    line = draw(st.sampled_from(lines)) if lines else ""
    return text + line * draw(st.sampled_from((1, 100)))


UNIT_RANGES = (
    (("x_m", "y_m"), (-1e5, 1e5)),
    (("_mps2",), (0.0, 1e4)),
    (("_mps",), (0.0, 150.0)),
    (("_m",), (0.0, 1e5)),
    (("_deg",), (-720.0, 720.0)),
    (("_s",), (0.0, 100.0)),
)
"""Ranges drawn for a numeric field by the unit in its name: inside vrusim's physical bounds (docs/limits.md)."""
RUN_RANGES = {"duration_s": (0.01, 5.0), "dt_s": (0.001, 0.1)}
"""Fields of `sim` kept small so that an extreme scenario still runs in a second or two."""


def _numeric_paths(value: Any, prefix: tuple = ()) -> list[tuple]:
    """Paths to every int or float (not bool) inside `value`."""
    return [
        path
        for path in _paths(value, prefix)
        if isinstance(_parent(value, path)[path[-1]], int | float)
        and not isinstance(_parent(value, path)[path[-1]], bool)
    ]


def _unit_range(name: str) -> tuple[float, float]:
    if name in RUN_RANGES:
        return RUN_RANGES[name]
    for suffixes, bounds in UNIT_RANGES:
        if name in suffixes or name.endswith(suffixes):
            return bounds
    return (-1e6, 1e6)


@st.composite
def extreme_physics(draw: st.DrawFn, base: dict) -> dict:
    """`base` with one to four numeric fields set to extreme values that are still inside the physical bounds
    (a range's ends, 0, tiny and huge): valid or refused by a cross-field check, never a crash or a NaN."""
    document = copy.deepcopy(base)
    for path in draw(st.lists(st.sampled_from(_numeric_paths(document)), min_size=1, max_size=4, unique=True)):
        name = next((key for key in reversed(path) if isinstance(key, str)), "")
        low, high = _unit_range(name)
        value = draw(st.sampled_from((low, high, 0.0, 1e-9)) | st.floats(low, high, allow_nan=False))
        _parent(document, path)[path[-1]] = value
    return document


def physics_texts() -> st.SearchStrategy[str]:
    """Valid-looking scenario files with extreme values inside the physical bounds."""
    return extreme_physics(base_scenario()).map(dump)


def base_scenario() -> dict:
    """The paper's pedestrian case, shortened to `SHORT_RUN_S`."""
    document = yaml.safe_load(BASE_SCENARIO.read_text(encoding="utf-8"))
    document.setdefault("sim", {})["duration_s"] = SHORT_RUN_S
    return document


def base_sweep() -> dict:
    """The bundled Monte Carlo spec with its base as an absolute path and `SWEEP_SAMPLES` samples."""
    document = yaml.safe_load(BASE_SWEEP.read_text(encoding="utf-8"))
    document["base"] = str((BASE_SWEEP.parent / document["base"]).resolve())
    document["samples"] = SWEEP_SAMPLES
    document["batch_size"] = SWEEP_SAMPLES
    return document


def scenario_texts() -> st.SearchStrategy[str]:
    """Malformed (and some still valid) scenario files."""
    return mutated(base_scenario()).map(dump).flatmap(corrupted_text)


def sweep_texts() -> st.SearchStrategy[str]:
    """Malformed (and some still valid) sweep specs."""
    return mutated(base_sweep()).map(dump).flatmap(corrupted_text)


XOSC_STEM = "fuzz"
"""File stem of the exported OpenSCENARIO pair (`fuzz.xosc` names its road `fuzz.xodr`)."""


@functools.cache
def exported_pair() -> tuple[str, str]:
    """(`.xosc` text, `.xodr` text) of the paper's pedestrian case as `vrusim export` writes it."""
    from vrusim.interop.openscenario import export_openscenario
    from vrusim.scenario.loading import scenario_from_mapping

    with tempfile.TemporaryDirectory() as folder:
        export_openscenario(scenario_from_mapping(base_scenario()), Path(folder), XOSC_STEM)
        return tuple(
            (Path(folder) / f"{XOSC_STEM}{suffix}").read_text(encoding="utf-8") for suffix in (".xosc", ".xodr")
        )


ATTRIBUTE = re.compile(r'="([^"]*)"')


@st.composite
def mutated_xml(draw: st.DrawFn, text: str) -> str:
    """XML text with one to three attribute values replaced by junk, a line removed or repeated, or an entity
    declaration or a processing instruction put in front; then possibly cut short or with a character inserted."""
    for _ in range(draw(st.integers(1, 3))):
        kind = draw(st.sampled_from(("attribute", "attribute", "attribute", "drop", "repeat", "prolog")))
        lines = text.splitlines(keepends=True)
        if kind == "attribute":
            spans = [m.span(1) for m in ATTRIBUTE.finditer(text)]
            start, end = draw(st.sampled_from(spans))
            value = draw(st.sampled_from(SPECIAL_STRINGS) | st.text(max_size=12) | st.floats().map(repr))
            text = text[:start] + value.replace('"', "&quot;").replace("<", "&lt;") + text[end:]
        elif kind in ("drop", "repeat") and len(lines) > 2:
            at = draw(st.integers(1, len(lines) - 2))
            text = "".join(lines[:at] + (lines[at : at + 1] * 20 if kind == "repeat" else []) + lines[at + 1 :])
        elif kind == "prolog":
            text = draw(st.sampled_from((
                '<!DOCTYPE a [<!ENTITY b "bbbbbbbb">]>\n', '<!DOCTYPE a SYSTEM "file:///etc/passwd">\n', "<?x y?>\n",
            ))) + text.split("\n", 1)[-1]  # fmt: skip
    return draw(corrupted_text(text))


XOSC_DATA = Path(__file__).parent / "data" / "xosc"
LOGIC_FILE = re.compile(r'<LogicFile filepath="([^"]+)"')


@functools.cache
def hand_written_pairs() -> tuple[tuple[str, str], ...]:
    """(`.xosc` text, `.xodr` text) of the hand-written import test files (every supported element; not those that
    need a catalog folder), each `.xosc` naming its road `fuzz_<n>.xodr`."""
    pairs = []
    for path in sorted(XOSC_DATA.glob("*/*.xosc")):
        text = path.read_text(encoding="utf-8")
        road = LOGIC_FILE.search(text)
        if road is None or "<Directory" in text or not (path.parent / road.group(1)).is_file():
            continue
        road_text = (path.parent / road.group(1)).read_text(encoding="utf-8")
        pairs.append((text.replace(road.group(0), f'<LogicFile filepath="{XOSC_STEM}_{len(pairs)}.xodr"'), road_text))
    return tuple(pairs)


def write_input(folder: Path, text: str, suffix: str) -> Path:
    """Write a drawn input file into `folder` (an `.xosc` with the roads it may name next to it); its path."""
    path = folder / (f"{XOSC_STEM}.xosc" if suffix == ".xosc" else f"input{suffix}")
    path.write_text(text, encoding="utf-8", errors="surrogatepass")
    if suffix == ".xosc":
        (folder / f"{XOSC_STEM}.xodr").write_text(exported_pair()[1], encoding="utf-8")
        for number, (_, road) in enumerate(hand_written_pairs()):
            (folder / f"{XOSC_STEM}_{number}.xodr").write_text(road, encoding="utf-8")
    return path


def xosc_texts() -> st.SearchStrategy[str]:
    """Malformed (and some still valid) OpenSCENARIO files: the exported pedestrian case, or one of the
    hand-written import test files (synchronisation, routes, clothoids, conditions, speed shapes, roads), with
    their `.xodr` unchanged next to them."""
    seeds = st.deferred(lambda: st.sampled_from((exported_pair()[0], *(x for x, _ in hand_written_pairs()))))
    return seeds.flatmap(mutated_xml)


OPTION_VALUES = (
    "",
    "-1",
    "0",
    "1e11",
    "100000000000",
    "nan",
    "inf",
    "on",
    "maybe",
    "x" * 300,
    "a/" * 2100,
    "tcp://nonexistent.invalid:1",
    "module:Class",
    "CPNA",
    "CPNA-25/20kph/day",
    "2023",
    "2026",
    "1999",
    "fsm,aeb",
    "ego.cruise_speed_mps",
)
"""Values tried for options: invalid, extreme, and a few valid ones (so later checks are reached)."""
COMMANDS: dict[str, tuple[bool, tuple[str, ...], tuple[str, ...]]] = {
    "run": (True, (), ("--planner", "--v2x", "--seed", "--json", "--trace", "--plot")),
    "list": (False, (), ("--protocol", "--json")),
    "ncap": (False, (), ("--scenario", "--protocol", "--planner", "--v2x", "--out", "--predictions", "--verify")),
    "compare": (True, (), ("--planners", "--seeds", "--seed", "--v2x", "--json")),
    "sweep": (True, (), ("--out", "--seed", "--workers", "--scheduler", "--batch-size", "--json")),
    "summarize": (True, (), ("--by", "--bins", "--metrics", "--plot", "--x", "--json")),
    "report": (True, ("--out",), ("--v2x", "--planner", "--seed", "--bins")),
    "export": (True, ("--format", "--out"), ("--v2x", "--night", "--force")),
    "import": (True, ("--out",), ("--force", "--json")),
}
"""Per command: whether it takes a source, its required options, the options the fuzzer adds (`sweep` always
gets `--dry-run`; `ncap` always a `--scenario`, so that a run stays short)."""
FLAGS = ("--json", "--dry-run", "--night", "--force")
OUTPUTS = ("--out", "--trace", "--plot", "--predictions")
OUTPUT_SUFFIXES = ("", ".csv", ".png", ".html", ".xlsx", ".parquet", ".yaml")
CHOICES = {"--format": ("openscenario", "commonroad", "xml"), "--scenario": ("CPNA", "CB", "CMRs", "XYZ", "")}
SOURCES = (
    "example:pedestrian-crossing",
    "CPNA-25/20kph/day",
    "missing.yaml",
    "missing.xosc",
    "",
    "x" * 300,
    "/dev/zero",
    ".",
)
"""Positional arguments tried."""


FOLDER = "{folder}"
"""Stands for a fresh output folder in drawn output paths (`with_folder` puts the real one in)."""


def with_folder(args: list[str], folder: str | Path) -> list[str]:
    """`args` with `FOLDER` replaced by `folder`."""
    return [arg.replace(FOLDER, str(folder)) for arg in args]


@st.composite
def cli_arguments(draw: st.DrawFn) -> list[str]:
    """A command with a source and up to four options with drawn values; output paths inside `FOLDER`."""
    command = draw(st.sampled_from(sorted(COMMANDS)))
    takes_source, required, optional = COMMANDS[command]
    args = [command]
    if takes_source:
        source = draw(st.sampled_from(SOURCES))
        args.append(str(BASE_SWEEP) if command == "sweep" and source.startswith("example") else source)
    options = [*required, *draw(st.lists(st.sampled_from(optional), max_size=4, unique=True))]
    if command == "ncap" and "--scenario" not in options:
        options.append("--scenario")
    for option in options:
        if option in FLAGS:
            args.append(option)
            continue
        value = draw(st.sampled_from(CHOICES.get(option, OPTION_VALUES)))
        if option in OUTPUTS and value not in ("", "x" * 300):
            value = f"{FOLDER}/out{draw(st.sampled_from(OUTPUT_SUFFIXES))}"
        args += [option, value]
    if command == "sweep":
        args.append("--dry-run")
    return args


@dataclass
class Verdict:
    """How vrusim answered one input."""

    exit_code: int | None
    output: str
    traceback: str | None = None
    notes: list[str] = field(default_factory=list)

    @property
    def acceptable(self) -> bool:
        """A result (exit 0) or one clear user error (exit 2 with a message), and no traceback."""
        if self.traceback is not None or "Traceback" in self.output:
            return False
        if self.exit_code == 0:
            return True
        return self.exit_code == 2 and bool(self.output.strip())


def invoke_cli(args: list[str]) -> Verdict:
    """`vrusim ARGS` in this process (Typer's runner); an exception other than SystemExit is a traceback."""
    import traceback

    from typer.testing import CliRunner

    from vrusim.cli.app import app

    result = CliRunner().invoke(app, args, catch_exceptions=True)
    error = result.exception
    if error is not None and not isinstance(error, SystemExit):
        text = "".join(traceback.format_exception(type(error), error, error.__traceback__))
        return Verdict(result.exit_code, result.output, text)
    return Verdict(result.exit_code, result.output)


def finite_results(output: str) -> bool:
    """No NaN or infinity in a JSON result printed by `--json` (an empty or non-JSON output passes)."""
    import json

    try:
        document = json.loads(output)
    except ValueError:
        return True

    def walk(value: Any) -> bool:
        if isinstance(value, float):
            return math.isfinite(value)
        if isinstance(value, dict):
            return all(walk(v) for v in value.values())
        if isinstance(value, list):
            return all(walk(v) for v in value)
        return True

    return walk(document)
