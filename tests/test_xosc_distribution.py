"""OpenSCENARIO expressions (`vrusim.formats.xosc_expression`), parameter distributions
(`vrusim.formats.xosc_distribution`) and `vrusim sweep DIST.xosc` (`vrusim.sweep.xosc_sweep`)."""

from __future__ import annotations

import json
import math
import re
import time
from pathlib import Path

import pyarrow.parquet as pq
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cli_helpers import assert_user_error, invoke
from vrusim.errors import UserInputError
from vrusim.formats.xosc_distribution import read_distribution
from vrusim.formats.xosc_expression import MAX_DEPTH, ExpressionError, _tokens, evaluate, value_text
from vrusim.formats.xosc_import import read_xosc, read_xosc_root

DATA = Path(__file__).parent / "data" / "xosc" / "distribution"
CPNA = DATA / "cpna.xosc"


# ----------------------------------------------------------------------------------------------- expressions


@pytest.mark.parametrize(
    ("text", "value"),
    [
        ("1 + 2 * 3", 7.0),
        ("(1 + 2) * 3", 9.0),
        ("10 - 4 - 3", 3.0),  # left-associative
        ("2 * 3 / 4", 1.5),
        ("7 % 3 + 1", 2.0),
        ("-7 % 3", -1.0),  # C remainder: the dividend's sign
        ("-2 * -3", 6.0),
        ("- (2 + 3)", -5.0),
        ("2.5e1 + .5", 25.5),
        ("$a * 2 + $b", 13.0),
        ("pow(2, 10)", 1024.0),
        ("sqrt(16) + abs(-3)", 7.0),
        ("min(3, $a) + max(1, 2)", 5.0),
        ("round(2.5) + round(-2.5)", 0.0),  # halves away from zero
        ("round(0.49)", 0.0),
        ("floor(-1.5) + ceil(1.2)", 0.0),
        ("sign(-4) + sign(0) + sign(3)", 0.0),
        ("sin(0) + cos(0) + tan(0) + asin(0) + acos(1) + atan(0)", 1.0),
        ("1 + 2 < 4", True),
        ("1 == 1.0", True),
        ("1 != 1", False),
        ("2 >= 3 or 3 <= 3", True),
        ("not 1 > 2 and true", True),
        ("not (true and false)", True),
        ("true or false and false", True),  # and binds tighter than or
        ("$flag == false", True),
    ],
)
def test_expression_values(text: str, value: float | bool) -> None:
    result = evaluate(text, {"a": 5.0, "b": 3.0, "flag": False})
    assert result == value and type(result) is type(value)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("1 / 0", "division by zero"),
        ("1 % (2 - 2)", "by zero"),
        ("$missing + 1", "'missing' is not declared"),
        ("$name + 1", "is a string"),
        ("sqrt(-1)", "non-finite"),
        ("pow(10, 400)", "non-finite"),
        ("1e308 * 10", "non-finite"),
        ("1 +", "the end"),
        ("(1 + 2", "expected ')'"),
        ("1 2", "after a complete expression"),
        ("1 < 2 < 3", "after a complete expression"),
        ("true + 1", "needs numbers"),
        ("not 1", "needs booleans"),
        ("1 == true", "compares a boolean"),
        ("pow(2)", "takes 2 arguments"),
        ("exp(1)", "unknown function"),
        ("__import__('os')", "unexpected \"'os')\" at character 12"),
        ("1 ; 2", "unexpected '; 2' at character 2"),
        ("(" * 10_000 + "1" + ")" * 10_000, "nested more than"),
        ("-" * 10_000 + "1", "nested more than"),
        ("not " * 10_000 + "true", "nested more than"),
    ],
)
def test_expression_errors(text: str, message: str) -> None:
    with pytest.raises(ExpressionError, match=re.escape(message)):
        evaluate(text, {"name": "a string"})


def test_nesting_up_to_the_limit_is_fine() -> None:
    assert evaluate("(" * MAX_DEPTH + "1" + ")" * MAX_DEPTH, {}) == 1.0


def test_tokenizing_is_linear_in_the_text() -> None:
    """Each token copied the rest of the text (`text[position:].isspace()`): a 1.88 MB `${1+1+...}` took minutes.
    40,000 long numbers (2 MB) took seconds that way; now tens of milliseconds."""
    text = "+".join(["1." + "0" * 48] * 40_000) + "  "
    started = time.perf_counter()
    tokens = _tokens(text)
    assert time.perf_counter() - started < 1.0
    assert len(tokens) == 80_000 and tokens[-1] == ("end", "")


def test_value_text() -> None:
    assert [value_text(v) for v in (3.0, -0.5, True, False, 1e20)] == ["3", "-0.5", "true", "false", "1e+20"]


# random expression trees: rendered with the fewest brackets precedence allows, evaluated by Python directly

_PRECEDENCE = {"+": 1, "-": 1, "*": 2, "/": 2, "%": 2}


def _trees():
    leaves = st.integers(0, 50).map(float) | st.sampled_from([0.5, 2.25, 1e-3])
    return st.recursive(
        leaves,
        lambda inner: st.tuples(st.sampled_from(list(_PRECEDENCE)), inner, inner) | st.tuples(st.just("neg"), inner),
        max_leaves=25,
    )


def _render(tree) -> tuple[str, int]:
    """(text, precedence of its top operator: 3 for a number or a negation)."""
    if isinstance(tree, float):
        return repr(tree), 3
    if tree[0] == "neg":
        text, precedence = _render(tree[1])
        return "-" + (text if precedence == 3 else f"({text})"), 3
    op, left, right = tree
    (lt, lp), (rt, rp) = _render(left), _render(right)
    lt = lt if lp >= _PRECEDENCE[op] else f"({lt})"
    rt = rt if rp > _PRECEDENCE[op] else f"({rt})"
    return f"{lt} {op} {rt}", _PRECEDENCE[op]


def _python(tree) -> float:
    """The tree's value by Python's arithmetic; ZeroDivisionError / OverflowError when it has none."""
    if isinstance(tree, float):
        return tree
    if tree[0] == "neg":
        return -_python(tree[1])
    op, left, right = tree
    a, b = _python(left), _python(right)
    if op in "/%" and b == 0:
        raise ZeroDivisionError
    value = {"+": a + b, "-": a - b, "*": a * b, "/": a / b if b else 0.0, "%": math.fmod(a, b) if b else 0.0}[op]
    if not math.isfinite(value):
        raise OverflowError
    return value


@settings(max_examples=300, deadline=None)
@given(_trees())
def test_expression_matches_python_arithmetic(tree) -> None:
    text, _ = _render(tree)
    try:
        expected = _python(tree)
    except (ZeroDivisionError, OverflowError):
        with pytest.raises(ExpressionError):
            evaluate(text, {})
        return
    assert evaluate(text, {}) == expected, text


# ----------------------------------------------------------------------------------------------- in a file


def _scenario_with(tmp_path: Path, declarations: str, speed: str = "$EgoInitialSpeed_mps") -> Path:
    """The CPNA test file with its parameter declarations replaced and the ego's target speed set to `speed`."""
    text = CPNA.read_text()
    start, end = text.index("<ParameterDeclarations>"), text.index("</ParameterDeclarations>")
    text = text[:start] + f"<ParameterDeclarations>{declarations}" + text[end:]
    text = text.replace(
        '<AbsoluteTargetSpeed value="$EgoInitialSpeed_mps"/>', f'<AbsoluteTargetSpeed value="{speed}"/>'
    )
    (tmp_path / "cpna.xodr").write_text((DATA / "cpna.xodr").read_text())
    path = tmp_path / "case.xosc"
    path.write_text(text)
    return path


def test_file_expressions_and_overrides() -> None:
    assert read_xosc(CPNA).ego.cruise_speed_mps == pytest.approx(20 / 3.6)
    base = read_xosc(CPNA).vrus[0].start.y_m
    moved = read_xosc(CPNA, {"EgoSpeed_kph": "36", "ImpactPosition": "0.75"})
    assert moved.ego.cruise_speed_mps == pytest.approx(10.0)
    assert moved.vrus[0].start.y_m == pytest.approx(base + 0.9)  # derived declaration re-evaluated
    with pytest.raises(UserInputError, match=r"'Nope'.*not declared"):
        read_xosc(CPNA, {"Nope": "1"})
    with pytest.raises(UserInputError, match=r"ImpactPosition.*expected a number"):
        read_xosc(CPNA, {"ImpactPosition": "left"})


_REST = (
    '<ParameterDeclaration name="Vru0InitialSpeed_mps" parameterType="double" value="0"/>'
    '<ParameterDeclaration name="Vru0TriggerEgoTravel_m" parameterType="double" value="5"/>'
    '<ParameterDeclaration name="Vru0TopSpeed_mps" parameterType="double" value="1.4"/>'
    '<ParameterDeclaration name="Vru0Accel_mps2" parameterType="double" value="1"/>'
    '<ParameterDeclaration name="SimDuration_s" parameterType="double" value="10"/>'
    '<ParameterDeclaration name="ImpactPosition" parameterType="double" value="0.25"/>'
    '<ParameterDeclaration name="Vru0StartY_m" parameterType="double" value="-6.14"/>'
)


@pytest.mark.parametrize(
    ("declarations", "speed", "message"),
    [
        ('<ParameterDeclaration name="V" parameterType="double" value="${1 / 0}"/>', "$V", "division by zero"),
        ('<ParameterDeclaration name="V" parameterType="double" value="5"/>', "${$V * $W}", "'W' is not declared"),
        (
            '<ParameterDeclaration name="V" parameterType="double" value="5"/>',
            "${$V +}",
            "expression '\\$\\{\\$V \\+\\}'",
        ),
        ('<ParameterDeclaration name="V" parameterType="int" value="${5 / 2}"/>', "$V", "expected a whole number"),
        ('<ParameterDeclaration name="V" parameterType="unsignedInt" value="-1"/>', "$V", "expected a whole number"),
        ('<ParameterDeclaration name="V" parameterType="boolean" value="yes"/>', "$V", "expected true or false"),
        ('<ParameterDeclaration name="V" parameterType="dateTime" value="noon"/>', "$V", "ISO 8601"),
        ('<ParameterDeclaration name="V" parameterType="float" value="1"/>', "$V", "parameterType.*unknown"),
        ('<ParameterDeclaration name="V" parameterType="string" value="x"/>', "${$V + 1}", "is a string"),
        ('<ParameterDeclaration name="V" parameterType="double" value="1"/>', "${" + "(" * 10_000 + "}", "nested more"),
    ],
)
def test_file_expression_errors_name_file_line_and_expression(
    tmp_path: Path, declarations: str, speed: str, message: str
) -> None:
    path = _scenario_with(tmp_path, declarations + _REST, speed)
    with pytest.raises(UserInputError, match=message) as error:
        read_xosc(path)
    assert str(error.value).startswith(f"{path}: line ")


def test_file_typed_parameters(tmp_path: Path) -> None:
    declarations = (
        '<ParameterDeclaration name="N" parameterType="int" value="${round(4.5)}"/>'
        '<ParameterDeclaration name="On" parameterType="boolean" value="${$N == 5}"/>'
        '<ParameterDeclaration name="V" parameterType="double" value="${$On and $N > 4}"/>'
    )
    with pytest.raises(UserInputError, match=r"'V'.*expected a number, got 'true'"):
        read_xosc(_scenario_with(tmp_path, declarations + _REST, "$N"))
    declarations = declarations.replace('"double" value="${$On and $N > 4}"', '"double" value="${$N * 2}"')
    assert read_xosc(_scenario_with(tmp_path, declarations + _REST, "$V")).ego.cruise_speed_mps == 10.0


# ----------------------------------------------------------------------------------------------- distributions


def _sets(path: Path):
    return read_distribution(*read_xosc_root(path))


def test_single_parameter_factorial_10x3() -> None:
    sets = _sets(DATA / "cpna_10x3.xosc")
    assert sets.names == ("EgoSpeed_kph", "ImpactPosition") and sets.kind == "deterministic"
    assert len(sets.rows) == 30
    assert sets.rows[:4] == (("15", "0.25"), ("15", "0.5"), ("15", "0.75"), ("20", "0.25"))
    assert [row[0] for row in sets.rows[::3]] == [str(v) for v in range(15, 61, 5)]


def test_range_endpoints_and_steps() -> None:
    sets = _sets(DATA / "cpna_100.xosc")
    assert len(sets.rows) == 100
    expected = [f"{0.05 + i / 10:.2f}" for i in range(10)]
    assert [row[1] for row in sets.rows[:10]] == expected


def test_multi_parameter_sets_times_a_set() -> None:
    sets = _sets(DATA / "multi_set.xosc")
    assert sets.names == ("EgoSpeed_kph", "ImpactPosition", "Vru0TopSpeed_mps")
    assert [row[:2] for row in sets.rows] == [("20", "0.25")] * 3 + [("40", "0.75")] * 3
    assert [row[2] for row in sets.rows[:3]] == ["1.0", "1.3888888888888888", "2.0"]  # an expression value


def test_stochastic_draws_are_in_range_and_seeded() -> None:
    sets = _sets(DATA / "stochastic.xosc")
    assert sets.kind == "stochastic" and len(sets.rows) == 40
    speeds = [float(row[0]) for row in sets.rows]
    positions = [float(row[1]) for row in sets.rows]
    assert all(10 <= v < 60 for v in speeds) and len(set(speeds)) == 40
    assert all(0.2 <= v <= 0.8 for v in positions)
    assert sets.rows == _sets(DATA / "stochastic.xosc").rows


def test_stochastic_seed_changes_the_draws(tmp_path: Path) -> None:
    text = (DATA / "stochastic.xosc").read_text().replace('randomSeed="7"', 'randomSeed="8"')
    (tmp_path / "cpna.xosc").write_text(CPNA.read_text())
    (tmp_path / "s.xosc").write_text(text)
    assert _sets(tmp_path / "s.xosc").rows != _sets(DATA / "stochastic.xosc").rows


def _distribution(tmp_path: Path, body: str) -> Path:
    (tmp_path / "cpna.xosc").write_text(CPNA.read_text())
    path = tmp_path / "d.xosc"
    path.write_text(
        '<OpenSCENARIO><FileHeader revMajor="1" revMinor="3" date="2026-01-01T00:00:00" description="" author=""/>'
        f'<ParameterValueDistribution><ScenarioFile filepath="cpna.xosc"/>\n{body}'
        "</ParameterValueDistribution></OpenSCENARIO>"
    )
    return path


@pytest.mark.parametrize(
    ("body", "message"),
    [
        ("<Deterministic/>", "has no distribution"),
        (
            '<Deterministic><DeterministicSingleParameterDistribution parameterName="A"><DistributionRange '
            'stepWidth="0"><Range lowerLimit="0" upperLimit="1"/></DistributionRange>'
            "</DeterministicSingleParameterDistribution></Deterministic>",
            "stepWidth > 0",
        ),
        (
            '<Deterministic><DeterministicSingleParameterDistribution parameterName="A"><UserDefinedDistribution/>'
            "</DeterministicSingleParameterDistribution></Deterministic>",
            "UserDefinedDistribution> is not supported",
        ),
        (
            '<Stochastic numberOfTestRuns="3"><StochasticDistribution parameterName="A"><PoissonDistribution '
            'expectedValue="1"/></StochasticDistribution></Stochastic>',
            "PoissonDistribution> is not supported",
        ),
        (
            '<Stochastic numberOfTestRuns="2.5"><StochasticDistribution parameterName="A"><UniformDistribution>'
            '<Range lowerLimit="0" upperLimit="1"/></UniformDistribution></StochasticDistribution></Stochastic>',
            "numberOfTestRuns",
        ),
        (
            '<Stochastic numberOfTestRuns="3"><StochasticDistribution parameterName="A"><NormalDistribution '
            'expectedValue="0" variance="1"><Range lowerLimit="50" upperLimit="51"/></NormalDistribution>'
            "</StochasticDistribution></Stochastic>",
            "rejects nearly every draw",
        ),
        ("<Deterministic/><Stochastic/>", "exactly one of"),
        # an OverflowError (cannot convert float infinity to integer) before the count was checked
        (
            '<Deterministic><DeterministicSingleParameterDistribution parameterName="A"><DistributionRange '
            'stepWidth="1e-320"><Range lowerLimit="15" upperLimit="60"/></DistributionRange>'
            "</DeterministicSingleParameterDistribution></Deterministic>",
            r"d\.xosc: line 2: <DistributionRange> values: inf variants exceeds the limit of 10,000,000",
        ),
        (
            '<Deterministic><DeterministicSingleParameterDistribution parameterName="A"><DistributionRange '
            'stepWidth="1"><Range lowerLimit="-1e308" upperLimit="1e308"/></DistributionRange>'
            "</DeterministicSingleParameterDistribution></Deterministic>",
            r"line 2: <Range> attribute lowerLimit: -1e\+308 exceeds the limit of 10,000,000,000",
        ),
        (
            '<Deterministic><DeterministicSingleParameterDistribution parameterName="A"><DistributionRange '
            'stepWidth="1e-9"><Range lowerLimit="-1e10" upperLimit="1e10"/></DistributionRange>'
            "</DeterministicSingleParameterDistribution></Deterministic>",
            r"<DistributionRange> values: 2\.0+2e\+19 variants exceeds",
        ),
        # numpy's OverflowError (high - low range exceeds valid bounds)
        (
            '<Stochastic numberOfTestRuns="3"><StochasticDistribution parameterName="A"><UniformDistribution>'
            '<Range lowerLimit="-1e308" upperLimit="1e308"/></UniformDistribution></StochasticDistribution>'
            "</Stochastic>",
            r"line 2: <Range> attribute lowerLimit: -1e\+308 exceeds the limit",
        ),
    ],
)
def test_distribution_errors(tmp_path: Path, body: str, message: str) -> None:
    with pytest.raises(UserInputError, match=message):
        _sets(_distribution(tmp_path, body))


def test_more_sets_than_distribution_variants_are_refused_before_any_is_imported(tmp_path: Path, monkeypatch) -> None:
    """numberOfTestRuns="2000000" ran for minutes towards tens of GB: every set is a whole scenario import (about
    3 ms and 25 kB), far from the sweep_variants budget of a sweep spec; now refused at once."""
    monkeypatch.setattr("vrusim.sweep.xosc_sweep.parse_root", lambda *args, **kwargs: pytest.fail("imported"))
    (tmp_path / "cpna.xosc").write_text(CPNA.read_text())
    path = tmp_path / "s.xosc"
    path.write_text((DATA / "stochastic.xosc").read_text().replace('numberOfTestRuns="40"', 'numberOfTestRuns="20000"'))
    result = invoke("sweep", path, "--dry-run", "--out", tmp_path / "o")
    assert_user_error(result, "line 6: <Stochastic> numberOfTestRuns: 20,000 variants exceeds the limit of 10,000")
    assert "VRUSIM_LIMIT_DISTRIBUTION_VARIANTS" in result.output and not (tmp_path / "o").exists()


def test_a_trillion_sets_are_refused_before_any_is_made() -> None:
    with pytest.raises(UserInputError, match=r"sweep_variants|VRUSIM_LIMIT_SWEEP_VARIANTS") as error:
        _sets(DATA / "huge.xosc")
    assert "4,500,001 x 1,000,001 parameter sets" in str(error.value)


# ----------------------------------------------------------------------------------------------- vrusim sweep


def test_sweep_runs_the_10x3_distribution_in_one_batch(tmp_path: Path) -> None:
    out = tmp_path / "out"
    result = invoke("sweep", DATA / "cpna_10x3.xosc", "--out", out, "--json", "--workers", "1")
    assert result.exit_code == 0, result.output
    document = json.loads(result.stdout)
    assert (document["variants"], document["batches"]) == (30, 1)
    (chunk,) = sorted((out / "chunks").glob("*.parquet"))
    table = pq.read_table(chunk).to_pydict()
    sets = _sets(DATA / "cpna_10x3.xosc")
    assert table["param.EgoSpeed_kph"] == [float(row[0]) for row in sets.rows]
    assert table["param.ImpactPosition"] == [float(row[1]) for row in sets.rows]
    assert len({round(v, 9) for v in table["min_ttc_s"]}) >= 25  # the parameters reach the simulation
    manifest = json.loads((out / "manifest.json").read_text())
    assert [p["name"] for p in manifest["parameters"]] == ["param.EgoSpeed_kph", "param.ImpactPosition"]


def test_sweep_variants_are_the_imported_parameter_sets(tmp_path: Path) -> None:
    from vrusim.sweep.plan import VariantBuilder
    from vrusim.sweep.xosc_sweep import distribution_sweep

    sweep = distribution_sweep(DATA / "multi_set.xosc")
    variants = VariantBuilder(sweep.plan).bases
    expected = read_xosc(CPNA, {"EgoSpeed_kph": "40", "ImpactPosition": "0.75", "Vru0TopSpeed_mps": "2.0"})
    assert list(variants.values())[5].ego == expected.ego
    assert list(variants.values())[5].vrus == expected.vrus


def test_sweep_dry_run_and_resume(tmp_path: Path) -> None:
    dry = invoke("sweep", DATA / "multi_set.xosc", "--dry-run", "--json")
    assert dry.exit_code == 0 and json.loads(dry.stdout)["variants"] == 6
    out = tmp_path / "out"
    assert invoke("sweep", DATA / "multi_set.xosc", "--out", out, "--quiet", "--workers", "1").exit_code == 0
    resumed = invoke("sweep", DATA / "multi_set.xosc", "--out", out, "--resume", "--json", "--workers", "1")
    assert resumed.exit_code == 0 and json.loads(resumed.stdout)["batches_run"] == 0


def test_sweep_refuses_a_plain_scenario_and_run_refuses_a_distribution(tmp_path: Path) -> None:
    assert_user_error(invoke("sweep", CPNA, "--out", tmp_path / "o"), "not a parameter distribution", "vrusim run")
    assert_user_error(invoke("run", DATA / "cpna_10x3.xosc"), "parameter distribution", "vrusim sweep")
    assert_user_error(invoke("sweep", DATA / "huge.xosc", "--out", tmp_path / "h"), "VRUSIM_LIMIT_SWEEP_VARIANTS")
    assert not (tmp_path / "h").exists()
