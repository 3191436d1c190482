"""OpenSCENARIO import (`vrusim.formats.xosc_import`): export -> import round trips give the same runs, and input
outside the supported subset is one clear error naming the element."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

pytest.importorskip("scenariogeneration")

from cli_helpers import invoke
from vrusim.engine.simulate import simulate
from vrusim.errors import UserInputError
from vrusim.formats.xosc_import import read_xosc
from vrusim.interop.openscenario import export_openscenario
from vrusim.metrics.summary import summary_rows
from vrusim.ncap.build import build_test
from vrusim.ncap.grid import select
from vrusim.paper.cases import scenario_dir
from vrusim.scenario.loading import load_scenario
from vrusim.scenario.schema import Scenario
from vrusim.scenario.settings import with_settings
from xosc_helpers import edited, refused

CATALOGUE = {
    "2023": ["CPNA", "CPFA", "CPLA", "CBLA", "CPTAfs", "CMRs", "CPRA"],
    "2026": ["CPNA", "CPTAno", "CMRs", "CPMRCm", "CMFtap", "CBNAO"],
}
"""Catalogue codes sampled per edition (first and last test of each)."""

NOT_EXPORTED = {
    "": ("sensor", "v2x", "planner", "metrics"),
    "sim": ("dt_s", "seed"),
    "ego": ("max_jerk_mps3", "actuator_lag_s", "tracking", "driver", "door", "mass_kg"),
}
"""Fields an OpenSCENARIO export does not carry (docs/interop.md): copied from the original before comparing."""
VRU_NOT_EXPORTED = ("speed_time_constant_s", "motion", "mass_kg")


def _cases() -> list[Scenario]:
    cases = [load_scenario(path) for path in sorted(scenario_dir().glob("*.yaml"))]
    for protocol, codes in CATALOGUE.items():
        for code in codes:
            tests = select(codes=[code], protocol=protocol)
            cases += [
                build_test(test).scenario
                for test in {tests[0].test_id: tests[0], tests[-1].test_id: tests[-1]}.values()
            ]
    return cases


CASES = _cases()


def _with_unexported(original: Scenario, imported: Scenario) -> Scenario:
    data, source = imported.model_dump(), original.model_dump()
    for section, names in NOT_EXPORTED.items():
        target, origin = (data, source) if not section else (data[section], source[section])
        for name in names:
            target[name] = origin[name]
    for vru, origin in zip(data["vrus"], source["vrus"], strict=True):
        for name in VRU_NOT_EXPORTED:
            vru[name] = origin[name]
    return Scenario.model_validate(data)


def _round_trip(scenario: Scenario, folder: Path) -> Scenario:
    export_openscenario(scenario, folder, "case")
    return read_xosc(folder / "case.xosc")


def _row(scenario: Scenario, planner: str) -> dict:
    return summary_rows(simulate([with_settings(scenario, planner=planner)]))[0]


@pytest.mark.parametrize("scenario", CASES, ids=[s.name for s in CASES])
def test_a_round_trip_runs_as_the_original(scenario, tmp_path):
    imported = _with_unexported(scenario, _round_trip(scenario, tmp_path))
    for planner in ("none", "fsm"):
        before, after = _row(scenario, planner), _row(imported, planner)
        assert after["outcome"] == before["outcome"], planner
        assert after["impact_side"] == before["impact_side"], planner
        if before["contact_time_s"] is None:
            assert after["contact_time_s"] is None, planner
            continue
        assert after["contact_time_s"] == pytest.approx(before["contact_time_s"], abs=0.01), planner
        for axis in ("impact_point_x_m", "impact_point_y_m"):
            assert after[axis] == pytest.approx(before[axis], abs=0.02), (planner, axis)


def test_the_sample_has_contacts_and_misses():
    """The round trips compare both kinds of run (a sample of only misses would compare little)."""
    outcomes = {_row(s, "none")["contact_time_s"] is None for s in CASES}
    assert outcomes == {True, False}


@pytest.mark.parametrize("code", ["CPTAfs", "CMFtap-SfS"])
def test_the_route_and_vru_fields_come_back(code, tmp_path):
    """A clothoid turn (also one the ego starts inside) is recovered field by field (arc lengths from chords and
    heading changes: 1e-7 relative); a VRU keeps its type, speeds and footprint."""
    test = select(codes=[code], protocol="2026")[0]
    scenario = build_test(test).scenario
    imported = _round_trip(scenario, tmp_path)
    route, back = scenario.ego.route, imported.ego.route
    assert back.kind == route.kind
    for name in ("turn_at_m", "radius_m", "angle_deg", "clothoid_angle_deg", "length_m", "start_in_turn_m"):
        assert getattr(back, name) == pytest.approx(getattr(route, name), rel=1e-7, abs=1e-7), name
    assert back.clothoid_entry_radius_m == pytest.approx(route.clothoid_entry_radius_m, rel=1e-5)
    vru, got = scenario.vrus[0], imported.vrus[0]
    assert (got.type, got.speed_mps, got.accel_mps2, got.footprint_m) == (
        vru.type,
        pytest.approx(vru.speed_mps),
        pytest.approx(vru.accel_mps2),
        vru.footprint_m,
    )


def test_a_brake_and_a_time_trigger_come_back(tmp_path):
    base = load_scenario(scenario_dir() / "pedestrian_crossing.yaml")
    scenario = base.replace(
        **{"vrus[0].trigger": {"at_time_s": 0.7}, "vrus[0].brake": {"after_trigger_s": 1.5, "decel_mps2": 3.0}}
    )
    got = _round_trip(scenario, tmp_path).vrus[0]
    assert got.trigger.at_time_s == pytest.approx(0.7)
    assert got.brake is not None
    assert (got.brake.after_trigger_s, got.brake.decel_mps2) == (pytest.approx(1.5), pytest.approx(3.0))


# --------------------------------------------------------------------------------------------- CLI and sources


def test_import_writes_a_yaml_that_loads_as_the_same_scenario(tmp_path):
    scenario = CASES[0]
    export_openscenario(scenario, tmp_path, "case")
    out = tmp_path / "imported.yaml"
    result = invoke("import", str(tmp_path / "case.xosc"), "--out", str(out))
    assert result.exit_code == 0, result.output
    assert load_scenario(out) == read_xosc(tmp_path / "case.xosc")
    again = invoke("import", str(tmp_path / "case.xosc"), "--out", str(out))
    assert again.exit_code == 2 and "--force" in again.output


@pytest.mark.parametrize("name", ["case.xosc", "sub/../case.xosc", "hard.xosc"])
def test_import_refuses_to_write_over_its_source(tmp_path, name):
    """`--out X.xosc --force` replaced the source .xosc by the YAML (exit 0)."""
    export_openscenario(CASES[0], tmp_path, "case")
    source = tmp_path / "case.xosc"
    (tmp_path / "sub").mkdir()
    (tmp_path / "hard.xosc").hardlink_to(source)
    before = source.read_bytes()
    result = invoke("import", str(source), "--out", str(tmp_path / name), "--force")
    assert result.exit_code == 2 and "Traceback" not in result.output, result.output
    assert "--out:" in result.output and "is the FILE.xosc being read" in " ".join(result.output.split())
    assert source.read_bytes() == before


def test_run_and_load_take_a_xosc(tmp_path):
    import vrusim

    scenario = CASES[0]
    export_openscenario(scenario, tmp_path, "case")
    assert vrusim.load(str(tmp_path / "case.xosc")) == read_xosc(tmp_path / "case.xosc")
    result = invoke("run", str(tmp_path / "case.xosc"), "--planner", "none", "--json")
    assert result.exit_code == 0, result.output
    assert '"outcome"' in result.output


# --------------------------------------------------------------------------------------------- hostile input


def _exported(tmp_path: Path) -> Path:
    export_openscenario(CASES[0], tmp_path, "case")
    return tmp_path / "case.xosc"


def test_an_unsupported_action_is_refused_with_its_line(tmp_path):
    path = edited(
        _exported(tmp_path),
        "<TeleportAction>",
        '<ActivateControllerAction longitudinal="true"/></PrivateAction><PrivateAction><TeleportAction>',
    )
    message = refused(path, path.name, "<ActivateControllerAction>", "not supported")
    line = next(n for n, text in enumerate(path.read_text().splitlines(), 1) if "ActivateControllerAction" in text)
    assert f"line {line}" in message


def test_a_missing_logic_file_is_refused(tmp_path):
    path = _exported(tmp_path)
    (tmp_path / "case.xodr").unlink()
    refused(path, path.name, "<LogicFile>", "case.xodr", "not a file")


def test_no_logic_file_element_is_refused(tmp_path):
    path = edited(_exported(tmp_path), '<LogicFile filepath="case.xodr"/>', "")
    refused(path, path.name, "<RoadNetwork>", "<LogicFile>")


def test_a_reference_to_an_unknown_catalog_is_refused(tmp_path):
    path = _exported(tmp_path)
    text = path.read_text()
    start = text.index('<ScenarioObject name="vru0">') + len('<ScenarioObject name="vru0">')
    end = text.index("</ScenarioObject>", start)
    path.write_text(text[:start] + '<CatalogReference catalogName="People" entryName="adult"/>' + text[end:])
    refused(path, path.name, "<CatalogReference>", "line 36", "'People'", "no such catalog")


def test_an_undeclared_parameter_is_refused(tmp_path):
    path = edited(_exported(tmp_path), 'value="$SimDuration_s"', 'value="$Nowhere_s"')
    refused(path, path.name, "Nowhere_s", "not declared")


def test_an_assign_route_action_is_refused(tmp_path):
    path = _exported(tmp_path)
    text = path.read_text()
    start = text.index("<FollowTrajectoryAction>")
    end = text.index("</FollowTrajectoryAction>") + len("</FollowTrajectoryAction>")
    path.write_text(text[:start] + "<AssignRouteAction/>" + text[end:])
    refused(path, path.name, "<AssignRouteAction>", "FollowTrajectoryAction")


def test_a_night_time_of_day_sets_night_lighting(tmp_path):
    """The export writes the lighting as a time of day (12:00 day, 23:00 night); the import reads it back."""
    path = _exported(tmp_path)
    assert 'dateTime="2026-01-15T12:00:00"' in path.read_text()
    assert read_xosc(path).sensor.lighting == "day"
    edited(path, "T12:00:00", "T23:30:00")
    assert read_xosc(path).sensor.lighting == "night"
    edited(path, "T23:30:00", "T05:59:00")
    assert read_xosc(path).sensor.lighting == "night"


def test_night_tests_round_trip_their_lighting(tmp_path):
    test = select(codes=["CPNA"], night=True, protocol="2026")
    night = next(t for t in test if t.lighting == "night")
    scenario = build_test(night).scenario
    assert _round_trip(scenario, tmp_path).sensor.lighting == "night"


def test_weather_is_refused_not_skipped(tmp_path):
    environment = (
        '<GlobalAction><EnvironmentAction><Environment name="e"><TimeOfDay animation="false" '
        'dateTime="2024-06-01T12:00:00"/><Weather/></Environment></EnvironmentAction></GlobalAction>'
    )
    path = edited(_exported(tmp_path), "<Actions>", "<Actions>" + environment)
    with pytest.raises(UserInputError, match=re.escape("<Weather> is not supported")):
        read_xosc(path)
