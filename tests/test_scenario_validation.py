"""Bad scenario input gives one clear UserInputError whose message names the offending field (or file)."""

from __future__ import annotations

import os
import re
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from vrusim.engine.simulate import simulate
from vrusim.errors import UserInputError
from vrusim.scenario.loading import load_scenario, scenario_from_mapping
from vrusim.scenario.schema import Scenario

PAPER_FILES = sorted((Path(__file__).resolve().parents[1] / "scenarios" / "paper").glob("*.yaml"))


def field_lines(message: str) -> list[str]:
    """The per-field lines of a validation message (after the `<source>: invalid scenario` header)."""
    lines = message.splitlines()
    assert lines[0].endswith("invalid scenario"), message
    return [line.strip() for line in lines[1:]]


def rejected(data: Any) -> str:
    with pytest.raises(UserInputError) as info:
        scenario_from_mapping(data, "case.yaml")
    message = str(info.value)
    assert message.startswith("case.yaml: ")
    return message


def only_field(message: str) -> tuple[str, str]:
    """Assert exactly one offending field is reported; return (field path, reason)."""
    lines = field_lines(message)
    assert len(lines) == 1, message
    path, _, reason = lines[0].partition(": ")
    return path, reason


def set_vru0(key: str, value: Any) -> Callable[[dict], None]:
    def change(d: dict) -> None:
        d["vrus"][0][key] = value

    return change


CASES = [
    # (id, mutation of the minimal scenario, expected field path, regex the reason must match)
    (
        "unknown-field",
        lambda d: d["ego"].update(cruise_sped_mps=12.0),
        "ego.cruise_sped_mps",
        r"^unknown field$",
    ),
    ("unknown-top-level", lambda d: d.update(vehicle={}), "vehicle", r"^unknown field$"),
    (
        "string-speed",
        lambda d: d["ego"].update(cruise_speed_mps="fast"),
        "ego.cruise_speed_mps",
        r"^Input should be a valid number, got 'fast'$",
    ),
    # pydantic's lax mode would read these as 1.0, 12.5 and true; YAML 1.1 reads `on` / `yes` as true
    ("boolean-speed", lambda d: d["ego"].update(cruise_speed_mps=True), "ego.cruise_speed_mps", r"number, got true$"),
    ("quoted-number", set_vru0("top_speed_mps", "12.5"), "vrus[0].top_speed_mps", r"number, got '12.5'$"),
    ("boolean-in-point", set_vru0("start", [True, 2.0]), "vrus[0].start.x_m", r"valid number, got true"),
    ("number-for-switch", lambda d: d.update(v2x={"enabled": 1}), "v2x.enabled", r"^Input should be a valid boolean"),
    ("boolean-seed", lambda d: d.update(sim={"seed": False}), "sim.seed", r"valid integer, got false"),
    ("number-for-name", lambda d: d.update(name=7), "name", r"valid string, got 7"),
    ("mapping-for-list", lambda d: d.update(vrus={"type": "pedestrian"}), "vrus", r"^Input should be a list$"),
    ("negative-speed", set_vru0("top_speed_mps", -1.0), "vrus[0].top_speed_mps", r"greater than or equal to 0"),
    ("negative-initial-speed", set_vru0("initial_speed_mps", -0.5), "vrus[0].initial_speed_mps", r"greater than or"),
    (
        "zero-brake-decel",
        set_vru0("brake", {"after_trigger_s": 1.0, "decel_mps2": 0.0}),
        "vrus[0].brake.decel_mps2",
        r"greater than 0",
    ),
    (
        "trigger-route-and-time",
        set_vru0("trigger", {"at_time_s": 1.0, "ego_route_m": 3.0}),
        "vrus[0].trigger",
        r"exactly one",
    ),
    (
        "negative-cruise",
        lambda d: d["ego"].update(cruise_speed_mps=-3.0),
        "ego.cruise_speed_mps",
        r"greater than or",
    ),
    ("dt-zero", lambda d: d["sim"].update(dt_s=0.0), "sim.dt_s", r"greater than 0"),
    ("dt-negative", lambda d: d["sim"].update(dt_s=-0.01), "sim.dt_s", r"greater than 0"),
    (
        "dt-below-a-microsecond",  # 1e-200 s passed and overflowed the jerk to null
        lambda d: d["sim"].update(dt_s=1.0e-200, duration_s=1.0e-198),
        "sim.dt_s",
        r"at least 1e-06 s \(1 µs\), got 1e-200",
    ),
    ("fov-zero", lambda d: d.update(sensor={"fov_deg": 0}), "sensor.fov_deg", r"greater than 0"),
    ("fov-361", lambda d: d.update(sensor={"fov_deg": 361}), "sensor.fov_deg", r"less than or equal to 360"),
    (
        "vru-inside-ego",
        set_vru0("start", {"x_m": 1.0, "y_m": 0.5}),
        "vrus",
        r"vrus\[0\] starts overlapping the ego",
    ),
    (
        "trigger-two-conditions",
        set_vru0("trigger", {"at_time_s": 1.0, "ego_distance_m": 10.0, "point": [0.0, 0.0]}),
        "vrus[0].trigger",
        r"exactly one of",
    ),
    ("trigger-none", set_vru0("trigger", {}), "vrus[0].trigger", r"exactly one of"),
    ("trigger-no-point", set_vru0("trigger", {"ego_distance_m": 10.0}), "vrus[0].trigger", r"needs `point`"),
    ("v2x-without-rsu", lambda d: d.update(v2x={"enabled": True}), "v2x", r"rsu"),
    ("point-triple", set_vru0("start", [1.0, 2.0, 3.0]), "vrus[0].start", r"\[x_m, y_m\]"),
    ("nested-point-type", lambda d: d["ego"]["start"].update(x_m="left"), "ego.start.x_m", r"valid number"),
    ("no-vrus", lambda d: d.update(vrus=[]), "vrus", r"at least 1"),
    ("missing-ego", lambda d: d.pop("ego"), "ego", r"[Ff]ield required"),
    ("bad-vru-type", set_vru0("type", "horse"), "vrus[0].type", r"pedestrian"),
    (
        "route-too-short",
        lambda d: d["ego"].update(route={"kind": "left", "turn_at_m": 10, "length_m": 12}),
        "ego.route",
        r"length_m must cover",
    ),
]


@pytest.mark.parametrize(("mutate", "path", "reason"), [c[1:] for c in CASES], ids=[c[0] for c in CASES])
def test_bad_field_is_named(scenario_dict, mutate, path, reason):
    mutate(scenario_dict)
    got_path, got_reason = only_field(rejected(scenario_dict))
    assert got_path == path
    assert re.search(reason, got_reason), got_reason


def test_unknown_field_message_exact(scenario_dict):
    scenario_dict["ego"]["cruise_sped_mps"] = 12.0
    message = rejected(scenario_dict)
    assert "ego.cruise_sped_mps" in message
    assert "unknown field" in message
    assert message == "case.yaml: invalid scenario\n  ego.cruise_sped_mps: unknown field"


def test_every_offending_field_is_listed(scenario_dict):
    scenario_dict["sim"]["dt_s"] = 0.0
    scenario_dict["sensor"] = {"fov_deg": 400}
    lines = field_lines(rejected(scenario_dict))
    assert sorted(line.partition(":")[0] for line in lines) == ["sensor.fov_deg", "sim.dt_s"]


def test_vru_overlap_uses_the_rotated_ego(scenario_dict):
    """Ego heading +y (90°): a VRU 2 m ahead overlaps; one 2 m to the side (in x) does not."""
    scenario_dict["ego"]["start"] = {"x_m": 0.0, "y_m": 0.0, "heading_deg": 90.0}
    scenario_dict["vrus"][0]["start"] = {
        "x_m": 2.0,
        "y_m": 0.0,
    }  # 2 m to the right: clear of a 1.8 m wide car
    scenario_from_mapping(scenario_dict)
    scenario_dict["vrus"][0]["start"] = {"x_m": 0.0, "y_m": 2.0}  # inside the (4.5 m long) rotated rectangle
    path, reason = only_field(rejected(scenario_dict))
    assert path == "vrus"
    assert "vrus[0]" in reason


def test_second_vru_overlap_names_its_index(scenario_dict):
    scenario_dict["vrus"].append({"type": "cyclist", "start": [2.9, 0.0], "heading_deg": 0.0})
    path, reason = only_field(rejected(scenario_dict))
    assert path == "vrus"
    assert "vrus[1] starts overlapping" in reason


def test_top_level_list_is_rejected():
    with pytest.raises(UserInputError, match=r"^x\.yaml: expected a mapping"):
        scenario_from_mapping([{"name": "a"}], "x.yaml")


# ----------------------------------------------------------------------------------------------------------
# Files
# ----------------------------------------------------------------------------------------------------------
def test_missing_file(tmp_path):
    path = tmp_path / "nope.yaml"
    with pytest.raises(UserInputError) as info:
        load_scenario(path)
    assert str(info.value) == f"{path}: no such scenario file"


def test_invalid_yaml(tmp_path):
    path = tmp_path / "broken.yaml"
    path.write_text("name: [unclosed\nego: {start: \n", encoding="utf-8")
    with pytest.raises(UserInputError) as info:
        load_scenario(path)
    assert str(info.value).startswith(f"{path}: not valid YAML")


def test_yaml_merge_key_may_be_overridden(tmp_path):
    """`<<: *anchor` followed by an explicit key is YAML's override, not a repeated key."""
    from vrusim.scenario.yaml_file import read_yaml_file

    path = tmp_path / "merge.yaml"
    path.write_text("base: &b {x_m: 1.0, y_m: 2.0}\npoint:\n  <<: *b\n  y_m: 3.0\n", encoding="utf-8")
    assert read_yaml_file(path, "test") == {"base": {"x_m": 1.0, "y_m": 2.0}, "point": {"x_m": 1.0, "y_m": 3.0}}


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("- name: a\n- name: b\n", "expected a mapping of scenario fields at the top level"),
        # PyYAML keeps the last of two equal keys silently: a file must not mean something else than it reads
        (
            "name: a\nsim:\n  dt_s: 0.01\n  dt_s: 0.02\n",
            "not valid YAML (line 4, column 3: key 'dt_s' appears twice in one mapping)",
        ),
    ],
    ids=["list-at-top-level", "repeated-key"],
)
def test_bad_document_message(tmp_path, text, message):
    path = tmp_path / "bad.yaml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(UserInputError) as info:
        load_scenario(path)
    assert str(info.value) == f"{path}: {message}"


def test_empty_yaml(tmp_path):
    path = tmp_path / "empty.yaml"
    path.write_text("", encoding="utf-8")
    with pytest.raises(UserInputError, match="expected a mapping"):
        load_scenario(path)


def test_file_that_is_not_utf8(tmp_path):
    path = tmp_path / "binary.yaml"
    path.write_bytes(b"\xff\xfe\x00name: x\n")
    with pytest.raises(UserInputError) as info:
        load_scenario(path)
    assert str(info.value).startswith(f"{path}: cannot read scenario file")


def test_directory_instead_of_file(tmp_path):
    with pytest.raises(UserInputError) as info:
        load_scenario(tmp_path)
    assert str(info.value).startswith(f"{tmp_path}: not a regular file")


@pytest.mark.skipif(not hasattr(os, "geteuid") or os.geteuid() == 0, reason="root can read any file")
def test_unreadable_file(tmp_path):
    path = tmp_path / "secret.yaml"
    path.write_text("name: x\n", encoding="utf-8")
    path.chmod(0)
    try:
        with pytest.raises(UserInputError, match="cannot read scenario file"):
            load_scenario(path)
    finally:
        path.chmod(0o600)


def test_field_error_from_file_names_file_and_field(tmp_path):
    path = tmp_path / "bad_speed.yaml"
    path.write_text(
        "name: t\nego: {start: [0, 0], cruise_speed_mps: 10}\n"
        "vrus:\n  - {type: pedestrian, start: [30, -5], heading_deg: 90, top_speed_mps: -2}\n",
        encoding="utf-8",
    )
    with pytest.raises(UserInputError) as info:
        load_scenario(path)
    message = str(info.value)
    assert message.startswith(f"{path}: invalid scenario")
    assert only_field(message)[0] == "vrus[0].top_speed_mps"


def test_unknown_planner_parameter_is_named(scenario_dict):
    scenario_dict["planner"] = {"name": "fsm", "params": {"headway_sec": 2.0}}
    scenario = scenario_from_mapping(scenario_dict)
    with pytest.raises(UserInputError) as info:
        simulate([scenario])
    assert "planner.params.headway_sec" in str(info.value)
    assert "unknown field" in str(info.value)


# ----------------------------------------------------------------------------------------------------------
# The paper scenarios
# ----------------------------------------------------------------------------------------------------------
def test_three_paper_scenarios_present():
    assert sorted(p.name for p in PAPER_FILES) == [
        "escooter_leading.yaml",
        "motorcyclist_crossing.yaml",
        "pedestrian_crossing.yaml",
    ]


@pytest.mark.parametrize("path", PAPER_FILES, ids=lambda p: p.stem)
def test_paper_scenarios_load(path):
    scenario = load_scenario(path)
    assert isinstance(scenario, Scenario)
    assert scenario.name.startswith("paper-")
    assert scenario.ego.cruise_speed_mps > 0
    assert scenario.sensor.range_m == 20.0
    assert scenario.sensor.fov_deg == 120.0
    assert len(scenario.vrus) == 1
    # the model round-trips through a plain mapping unchanged
    assert scenario_from_mapping(scenario.model_dump(mode="json")) == scenario


def _scalar_leaves(data: Any, path: tuple = ()) -> list[tuple[tuple, Any]]:
    """(location, value) of every number and boolean in a YAML-like mapping."""
    if isinstance(data, dict):
        return [leaf for key, value in data.items() for leaf in _scalar_leaves(value, (*path, key))]
    if isinstance(data, list):
        return [leaf for i, value in enumerate(data) for leaf in _scalar_leaves(value, (*path, i))]
    return [(path, data)] if isinstance(data, bool | int | float) else []


def _replaced(data: Any, location: tuple, value: Any) -> Any:
    import copy

    out = copy.deepcopy(data)
    target = out
    for step in location[:-1]:
        target = target[step]
    target[location[-1]] = value
    return out


@pytest.mark.parametrize("name", ["pedestrian_crossing.yaml", "escooter_leading.yaml", "motorcyclist_crossing.yaml"])
def test_every_number_and_switch_of_a_paper_file_takes_only_its_type(name):
    """Each number of the paper files, given as a boolean or quoted, and each switch given as 1, is refused with
    exactly that field named (strict types everywhere, including nested models and lists). Planner parameters
    are checked by their planner when the run starts."""
    from vrusim.paper.cases import scenario_dir
    from vrusim.planners.registry import make_planner
    from vrusim.scenario.loading import field_path
    from vrusim.scenario.yaml_file import read_yaml_file
    from vrusim.sim.params import pack

    data = read_yaml_file(scenario_dir() / name, "scenario")
    leaves = _scalar_leaves(data)
    assert len(leaves) > 20
    for location, value in leaves:
        wrong = [1] if isinstance(value, bool) else [True, str(value)]
        for bad in wrong:
            if location[:2] == ("planner", "params"):
                scenario = scenario_from_mapping(_replaced(data, location, bad))
                with pytest.raises(
                    UserInputError, match=rf"{re.escape(field_path(location))}: Input should be a valid"
                ):
                    make_planner(scenario.planner.name).reset(pack([scenario]))
                continue
            path, reason = only_field(rejected(_replaced(data, location, bad)))
            assert path == field_path(location), (location, bad)
            assert reason.startswith("Input should be a valid"), reason


@pytest.mark.parametrize(
    ("field", "text", "reason"),
    [
        ("name", "a\x01b", "contains the control character U+0001 (character 2); expected one line"),
        ("name", "x\ud800y", "contains a lone surrogate U+D800 (character 2)"),
        ("name", "two\nlines", "contains the control character U+000A (character 4)"),
        ("description", "bad \x01 char", "contains the control character U+0001 (character 5); expected printable"),
        ("description", "x\ud800y", "contains a lone surrogate U+D800 (character 2)"),
        ("description", "c1 \x85", "contains the control character U+0085"),
        ("description", "no\ufffe", "contains the non-character U+FFFE"),
        ("obstacles[0].kind", "van\x1b[31m", "contains the control character U+001B (character 4)"),
    ],
)
def test_free_text_that_no_output_can_carry_is_refused(scenario_dict, field, text, reason):
    """Control characters and lone surrogates broke the export (XML) and the report (fonts) after loading."""
    if field.startswith("obstacles"):
        scenario_dict["obstacles"] = [{"kind": text, "centre": [0.0, 30.0], "length_m": 4.0, "width_m": 2.0}]
    else:
        scenario_dict[field] = text
    path, message = only_field(rejected(scenario_dict))
    assert path == field and reason in message


def test_free_text_keeps_tabs_line_breaks_and_any_printable_character(scenario_dict):
    scenario_dict.update(name="Ünïcödé 🚗 $x$ ‮", description="line 1\n\tline 2 €")
    scenario = scenario_from_mapping(scenario_dict)
    assert scenario.description == "line 1\n\tline 2 €"
