"""Hostile input (issue 18): every class of input that broke the "one clear message, exit 2, no traceback, nothing
on disk" promise, kept as a regression test. Limits: `vrusim.limits`, docs/limits.md."""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import pytest
import yaml

from cli_helpers import assert_user_error, invoke
from conftest import REPO_ROOT, minimal_scenario_dict
from vrusim.engine.simulate import simulate
from vrusim.errors import UserInputError
from vrusim.limits import LIMITS, check_limit, env_name, limit
from vrusim.metrics.summary import summary_rows
from vrusim.scenario.bounds import bound_of
from vrusim.scenario.loading import load_scenario
from vrusim.scenario.v2x import load_profiles
from vrusim.scenario.yaml_file import parse_yaml


def _write(tmp_path: Path, text: str, name: str = "scenario.yaml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def _scenario_text(**changes) -> str:
    data = minimal_scenario_dict()
    data.update(changes)
    return yaml.safe_dump(data)


@pytest.mark.parametrize("opening", ["[", "{a: "])
def test_deep_nesting_is_refused_with_the_limit_not_a_recursion_error(tmp_path, opening):
    closing = "]" if opening == "[" else "}"
    deep = _write(tmp_path, "name: x\nego: " + opening * 600 + "1" + closing * 600 + "\n")
    result = invoke("run", deep)
    assert_user_error(result, str(deep), "nested deeper than the limit of 32 levels", "docs/limits.md")
    sweep = _write(tmp_path, "base: scenario.yaml\nparameters: " + "[" * 600 + "]" * 600 + "\n", "sweep.yaml")
    assert_user_error(invoke("sweep", sweep, "--dry-run", "--out", tmp_path / "out"), "nested deeper")
    assert not (tmp_path / "out").exists()


def test_a_number_of_thousands_of_digits_is_refused_by_its_length(tmp_path):
    path = _write(tmp_path, "name: x\nsim: {duration_s: " + "9" * 5000 + "}\n")
    assert_user_error(invoke("run", path), "a number of 5,000 characters exceeds the limit of 64")


def test_an_alias_bomb_is_refused_before_it_is_expanded():
    rows = ["a0: &a0 [1, 1, 1, 1, 1, 1, 1, 1, 1, 1]"]
    rows += [f"a{k}: &a{k} [" + ", ".join([f"*a{k - 1}"] * 10) + "]" for k in range(1, 9)]  # 10^9 values
    with pytest.raises(yaml.YAMLError, match="values \\(aliases expanded\\) exceed the limit of 200,000"):
        parse_yaml("\n".join(rows))
    assert parse_yaml("a: &a [1, 2]\nb: *a\n") == {"a": [1, 2], "b": [1, 2]}  # aliases within the limit still work


def test_a_long_list_is_refused():
    with pytest.raises(yaml.YAMLError, match="a list of 100,001 items exceeds the limit of 100,000"):
        parse_yaml("[" + ", ".join(["0"] * 100_001) + "]")


@pytest.mark.skipif(not Path("/dev/zero").exists(), reason="needs /dev/zero")
@pytest.mark.parametrize("target", ["/dev/zero", "/dev/urandom"])
def test_a_symlink_to_a_device_is_not_read(tmp_path, target):
    link = tmp_path / "scenario.yaml"
    link.symlink_to(target)
    assert_user_error(invoke("run", link), str(link), "not a regular file")


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs FIFOs")
def test_a_fifo_without_a_writer_does_not_block(tmp_path):
    fifo = tmp_path / "scenario.yaml"
    os.mkfifo(fifo)
    assert_user_error(invoke("run", fifo), "not a regular file")


def test_a_file_over_the_size_limit_is_not_parsed(tmp_path, monkeypatch):
    big = _write(tmp_path, "name: x\n" + "# padding\n" * 250_000)  # 2.5 MB of valid YAML
    assert_user_error(invoke("run", big), f"{big}: {big.stat().st_size:,} bytes exceeds the limit of 2,000,000")
    monkeypatch.setenv(env_name("input_file_bytes"), "5000000")  # the limit is the user's to change
    assert_user_error(invoke("run", big), "invalid scenario")


def test_a_system_file_is_not_echoed_back(tmp_path):
    secret = _write(tmp_path, "".join(f"user{k}: secret{k}\n" for k in range(200)), "accounts.yaml")
    result = invoke("run", secret)
    assert_user_error(result, "not a scenario file")
    assert "secret" not in result.output.replace(str(secret), "") and len(result.output.splitlines()) <= 2


def test_a_scenario_with_many_bad_fields_lists_a_few():
    data = minimal_scenario_dict()
    data.update({f"unknown_{k}": k for k in range(50)})
    with pytest.raises(UserInputError) as info:
        from vrusim.scenario.loading import scenario_from_mapping

        scenario_from_mapping(data)
    lines = str(info.value).splitlines()
    assert len(lines) == 10 and lines[-1] == "  ... and 42 more"


@pytest.mark.parametrize(
    ("command", "argument", "name"),
    [("run", "SOURCE", "x" * 5000 + ".yaml"), ("report", "SOURCE", "x" * 300), ("summarize", "RESULTS", "x" * 300),
     ("compare", "SOURCE", "x" * 300), ("export", "SOURCE", "x" * 300)],
)  # fmt: skip
def test_a_path_beyond_the_os_limit_is_a_user_error(tmp_path, command, argument, name):
    """Class 6, inputs: a source or results folder whose name the OS cannot use (report and summarize were found
    by the fuzz campaign)."""
    long_path = str(tmp_path / name)
    extra = {"report": ("--out", tmp_path / "r.html"), "export": ("--format", "openscenario", "--out", tmp_path / "x")}
    result = invoke(command, long_path, *extra.get(command, ()))
    assert_user_error(result, argument, "File name too long")
    assert len(result.output) < 400 and not (tmp_path / "r.html").exists() and not (tmp_path / "x").exists()


def test_a_null_byte_in_a_sweep_base_is_a_user_error(tmp_path):
    spec = _write(tmp_path, 'base: "scen\\0ario.yaml"\nparameters: {ego.cruise_speed_mps: [10.0]}\n', "sweep.yaml")
    assert_user_error(invoke("sweep", spec, "--dry-run", "--out", tmp_path / "out"), "null byte")
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("model", [[1.0], {"a": 1}, None, 3])
def test_a_loss_model_that_is_not_a_name_is_a_user_error(tmp_path, model):
    """Class 4: `v2x.channel.loss: {model: [1.0]}` raised TypeError (unhashable) in the model registry."""
    path = _write(tmp_path, _scenario_text(v2x={"enabled": True, "channel": {"loss": {"model": model}}}))
    assert_user_error(invoke("run", path), "v2x.channel.loss")


def test_the_none_planner_refuses_parameters(tmp_path):
    path = _write(tmp_path, _scenario_text(planner={"name": "none", "params": {"zzz": 1}}))
    assert_user_error(invoke("run", path), "planner.params.zzz")


def test_limits_are_documented_and_changed_by_their_environment_variable(monkeypatch):
    text = (Path(__file__).resolve().parents[1] / "docs" / "limits.md").read_text()
    for name, entry in LIMITS.items():
        assert f"`{env_name(name)}`" in text and f"{entry.default:,.0f}" in text, name
    monkeypatch.setenv(env_name("yaml_depth"), "3")
    assert limit("yaml_depth") == 3
    with pytest.raises(yaml.YAMLError, match="limit of 3 levels"):
        parse_yaml("a: {b: {c: {d: 1}}}")
    for bad in ("0", "-1", "nan", "inf", "lots"):
        monkeypatch.setenv(env_name("yaml_depth"), bad)
        with pytest.raises(UserInputError, match="VRUSIM_LIMIT_YAML_DEPTH: expected a positive number"):
            limit("yaml_depth")
    monkeypatch.delenv(env_name("yaml_depth"))
    with pytest.raises(UserInputError, match=r"x\.yaml: 3,000,000 bytes exceeds the limit of 2,000,000"):
        check_limit("input_file_bytes", 3e6, "x.yaml")


def test_valid_files_still_load():
    for path in sorted((Path(__file__).resolve().parents[1] / "scenarios").rglob("*.yaml")):
        load_scenario(path)


@pytest.mark.parametrize("field", ["name", "description"])
def test_a_control_character_in_free_text_is_refused_before_export(tmp_path, field):
    path = _write(tmp_path, _scenario_text(**{field: "a\x01b"}))
    result = invoke("export", path, "--format", "openscenario", "--out", tmp_path / "out")
    assert_user_error(result, f"{field}: contains the control character U+0001")
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize(
    ("written", "reading"),
    [
        ("010", "010 is the octal number 8 in YAML 1.1; write 8 if you mean it, 10 if not (no leading zero)"),
        ("1:30", "1:30 is the base-60 number 90 in YAML 1.1; write 90 if you mean it, or '1:30' for text"),
        ("0b11", "0b11 is the binary number 3 in YAML 1.1; write 3 if you mean it"),
        ("1:30.5", "1:30.5 is the base-60 number 90.5"),
    ],
)
def test_a_yaml_1_1_number_that_reads_otherwise_is_refused_with_its_line(tmp_path, written, reading):
    text = _scenario_text().replace("cruise_speed_mps: 10.0", f"cruise_speed_mps: {written}")
    line = 1 + text.splitlines().index(f"  cruise_speed_mps: {written}")
    result = invoke("run", _write(tmp_path, text))
    assert_user_error(result, f"scenario.yaml: line {line}, column 21: {reading}")
    with pytest.raises(UserInputError, match="octal number 15"):
        load_profiles(_write(tmp_path, "mine: {latency_s: 017}\n", "profiles.yaml"))
    sweep = _write(tmp_path, "base: scenario.yaml\nsamples: 0b10\n", "sweep.yaml")
    assert_user_error(invoke("sweep", sweep, "--dry-run"), "sweep.yaml: line 2, column 10: 0b10 is the binary number 2")


def test_numbers_yaml_1_2_reads_alike_and_quoted_text_still_load():
    assert parse_yaml("[10, 0, -0, 0.5, 010.5, 1.0e+3, 0x1F, '010', \"1:30\", a0b1]") == [
        10, 0, 0, 0.5, 10.5, 1000.0, 31, "010", "1:30", "a0b1"
    ]  # fmt: skip


def test_a_gain_per_metre_is_no_length_and_a_huge_one_keeps_the_run_finite():
    """`heading_gain_per_m` (1/m) was bounded as a length ("1e+308 m exceeds the limit"); gains are unbounded
    (docs/limits.md) and 1e308 saturates the steering without NaN or inf."""
    assert bound_of("heading_gain_per_m") is None and bound_of("lateral_gain_per_m2") is None
    assert bound_of("cruise_gain_per_s") is None and bound_of("range_m") == "length_m"
    turning = load_scenario(REPO_ROOT / "scenarios" / "examples" / "right_turn_cyclist.yaml")
    huge = {"ego.tracking.heading_gain_per_m": 1e308, "ego.tracking.lateral_gain_per_m2": 1e308}
    run = simulate([turning, turning.replace(**huge)], trace=True)
    for name in ("ego_x_m", "ego_y_m", "ego_heading_x", "ego_curvature_per_m"):
        assert np.isfinite(run.trace[name]).all(), name
    assert all(math.isfinite(row["peak_lateral_accel_mps2"]) for row in summary_rows(run))
