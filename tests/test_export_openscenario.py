"""OpenSCENARIO / OpenDRIVE export: ASAM quality checks over the whole catalogue, round trip, triggers, CLI."""

from __future__ import annotations

import math
import tempfile
import time
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from lxml import etree

from asam_qc import check_files, checker_errors
from cli_helpers import assert_user_error, invoke
from vrusim.engine.simulate import simulate
from vrusim.interop.openscenario import build_export, export_openscenario, file_stem, road_half_length_m
from vrusim.interop.osc_motion import trigger_station_m
from vrusim.ncap.build import build_test
from vrusim.ncap.grid import select
from vrusim.scenario.loading import load_scenario
from vrusim.scenario.schema import Scenario

ROOT = Path(__file__).resolve().parents[1]
YAML_FILES = [*sorted(ROOT.glob("scenarios/paper/*.yaml")), *sorted(ROOT.glob("scenarios/examples/*.yaml"))]
DAY_TESTS = select(protocol="2023")
TEST_IDS = [test.test_id for test in DAY_TESTS]
NIGHT_SAMPLE = next(t for t in select(night=True, protocol="2023") if t.lighting == "night")
TOL = 1e-6


@pytest.fixture(scope="module")
def exported(tmp_path_factory) -> tuple[Path, dict[str, Scenario]]:
    """Every day catalogue test, one night test, the paper and example scenarios, exported into one folder."""
    folder = tmp_path_factory.mktemp("xosc")
    scenarios = [build_test(t).scenario for t in [*DAY_TESTS, NIGHT_SAMPLE]] + [load_scenario(f) for f in YAML_FILES]
    by_stem = {}
    for scenario in scenarios:
        export_openscenario(scenario, folder)
        by_stem[file_stem(scenario.name)] = scenario
    return folder, by_stem


# ----------------------------------------------------------------------------------------------- ASAM QC


def test_every_exported_file_passes_the_asam_quality_checkers(exported):
    folder, by_stem = exported
    files = sorted(folder.glob("*.xosc")) + sorted(folder.glob("*.xodr"))
    assert len(files) == 2 * len(by_stem) == 2 * (len(DAY_TESTS) + 1 + len(YAML_FILES))
    start = time.perf_counter()
    problems = {}
    for path, (issues, status) in check_files(files).items():
        if issues or checker_errors(status):
            problems[path.name] = issues + checker_errors(status)
        if path.suffix == ".xosc":  # every OpenSCENARIO checker applies to 1.3 and runs
            assert set(status.values()) == {"completed"}, (path.name, status)
        else:  # OpenDRIVE 1.5: the checkers defined from 1.7 / 1.8 are skipped
            assert status["check_asam_xodr_xml_valid_schema"] == "completed", (path.name, status)
    elapsed = time.perf_counter() - start
    assert problems == {}
    print(f"ASAM QC: {len(files)} files, 0 issues, {elapsed:.1f} s")


def test_the_checkers_find_issues_in_a_broken_export(exported, tmp_path):
    """The zero-issue result above means something: a broken .xosc and .xodr each get issues."""
    folder, by_stem = exported
    stem = next(iter(by_stem))
    xosc = etree.parse(str(folder / f"{stem}.xosc"))
    first, second = list(xosc.getroot().iter("ScenarioObject"))[:2]
    second.set("name", first.get("name"))  # two entities with one name
    xosc.write(str(tmp_path / "broken.xosc"))
    xodr = etree.parse(str(folder / f"{stem}.xodr"))
    lane = next(xodr.getroot().iter("lane"))
    lane.set("type", "no-such-lane-type")  # not in the schema's enumeration
    xodr.write(str(tmp_path / "broken.xodr"))
    for path, (issues, _) in check_files([tmp_path / "broken.xosc", tmp_path / "broken.xodr"]).items():
        assert issues, path.name


# ----------------------------------------------------------------------------------------------- round trip


class Xosc:
    """An exported .xosc read back with lxml; `value` resolves `$parameter` references."""

    def __init__(self, path: Path) -> None:
        self.root = etree.parse(str(path)).getroot()
        self.params = {p.get("name"): p.get("value") for p in self.root.iter("ParameterDeclaration")}

    def value(self, text: str) -> float:
        return float(self.params[text[1:]] if text.startswith("$") else text)

    def entity(self, name: str) -> etree._Element:
        return self.root.find(f"Entities/ScenarioObject[@name='{name}']")[0]

    def teleport(self, name: str) -> tuple[float, float, float]:
        position = self.root.find(
            f"Storyboard/Init/Actions/Private[@entityRef='{name}']//TeleportAction//WorldPosition"
        )
        return float(position.get("x")), float(position.get("y")), float(position.get("h"))

    def init_speed(self, name: str) -> float:
        private = self.root.find(f"Storyboard/Init/Actions/Private[@entityRef='{name}']")
        return self.value(private.find(".//AbsoluteTargetSpeed").get("value"))

    def event(self, name: str) -> etree._Element | None:
        return next((e for e in self.root.iter("Event") if e.get("name") == name), None)

    def box(self, name: str) -> tuple[float, float, float]:
        """(length, width, centre ahead of the reference point) of an entity's bounding box, m."""
        box = self.entity(name).find("BoundingBox")
        dims, centre = box.find("Dimensions"), box.find("Center")
        return float(dims.get("length")), float(dims.get("width")), float(centre.get("x"))


def _angle_gap(a: float, b: float) -> float:
    return abs((a - b + math.pi) % (2 * math.pi) - math.pi)


def assert_round_trip(path: Path, scenario: Scenario) -> None:
    """The exported file gives back the scenario's initial poses, headings, dimensions and speeds."""
    doc = Xosc(path)
    ego = scenario.ego
    length, width, ahead = doc.box("ego")
    assert abs(length - ego.length_m) < TOL and abs(width - ego.width_m) < TOL
    assert abs(ahead - (ego.length_m / 2 - ego.rear_overhang_m)) < TOL  # box centre ahead of the rear axle
    axles = doc.entity("ego").find("Axles")
    wheelbase = float(axles.find("FrontAxle").get("positionX")) - float(axles.find("RearAxle").get("positionX"))
    assert abs(wheelbase - ego.wheelbase_m) < TOL
    x, y, h = doc.teleport("ego")
    assert abs(x + ahead * math.cos(h) - ego.start.x_m) < TOL and abs(y + ahead * math.sin(h) - ego.start.y_m) < TOL
    assert _angle_gap(h, math.radians(ego.start.heading_deg)) < TOL
    sign = -1.0 if ego.reverse else 1.0
    assert abs(doc.init_speed("ego") - sign * ego.start_speed_mps) < TOL
    cruise = doc.event("ego_cruise")
    if cruise is not None:
        assert abs(doc.value(cruise.find(".//AbsoluteTargetSpeed").get("value")) - sign * ego.cruise_speed_mps) < TOL
    else:
        assert ego.cruise_speed_mps == ego.start_speed_mps
    for index, vru in enumerate(scenario.vrus):
        name = f"vru{index}"
        entity = doc.entity(name)
        expected_tag = "Pedestrian" if vru.type.value == "pedestrian" else "Vehicle"
        assert entity.tag == expected_tag
        if expected_tag == "Vehicle":
            category = {"motorcyclist": "motorbike"}.get(vru.type.value, "bicycle")
            assert entity.get("vehicleCategory") == category
        length, width, ahead = doc.box(name)
        assert abs(length / 2 - vru.footprint_m) < TOL and abs(width / 2 - vru.footprint_m) < TOL and ahead == 0.0
        x, y, h = doc.teleport(name)
        assert abs(x - vru.start.x_m) < TOL and abs(y - vru.start.y_m) < TOL
        first = vru.path[0] if vru.path else None
        heading = (
            math.radians(vru.heading_deg)
            if first is None
            else math.atan2(first.y_m - vru.start.y_m, first.x_m - vru.start.x_m)
        )
        assert _angle_gap(h, heading) < TOL
        assert abs(doc.init_speed(name) - vru.initial_speed_mps) < TOL
        start = doc.event(f"{name}_start")
        if start is not None:
            assert abs(doc.value(start.find(".//AbsoluteTargetSpeed").get("value")) - vru.speed_mps) < TOL
            rate = start.find(".//SpeedActionDynamics")
            assert rate.get("dynamicsDimension") == "rate" and abs(doc.value(rate.get("value")) - vru.accel_mps2) < TOL
        else:
            assert vru.speed_mps == vru.initial_speed_mps and vru.brake is None
    for index, box in enumerate(scenario.obstacles):
        name = f"obstacle{index}"
        length, width, ahead = doc.box(name)
        assert abs(length - box.length_m) < TOL and abs(width - box.width_m) < TOL
        x, y, h = doc.teleport(name)
        assert abs(x + ahead * math.cos(h) - box.centre.x_m) < TOL
        assert abs(y + ahead * math.sin(h) - box.centre.y_m) < TOL
        assert _angle_gap(h, math.radians(box.centre.heading_deg)) < TOL
    duration = doc.value(doc.root.find("Storyboard/StopTrigger//SimulationTimeCondition").get("value"))
    assert duration == scenario.sim.duration_s


@pytest.mark.parametrize("path", YAML_FILES, ids=lambda p: p.stem)
def test_paper_and_example_scenarios_round_trip(exported, path):
    folder, _ = exported
    scenario = load_scenario(path)
    assert_round_trip(folder / f"{file_stem(scenario.name)}.xosc", scenario)


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.sampled_from([*DAY_TESTS, NIGHT_SAMPLE]))
def test_catalogue_tests_round_trip(test):
    scenario = build_test(test).scenario
    with tempfile.TemporaryDirectory() as folder:
        xosc_path, xodr_path = export_openscenario(scenario, Path(folder))
        assert_round_trip(xosc_path, scenario)
        assert Xosc(xosc_path).root.find("RoadNetwork/LogicFile").get("filepath") == xodr_path.name


def test_scenariogeneration_parses_the_export_back(exported):
    from scenariogeneration import xosc

    folder, by_stem = exported
    stem = "paper-pedestrian-crossing"
    parsed = xosc.ParseOpenScenario(str(folder / f"{stem}.xosc"))
    names = [obj.name for obj in parsed.entities.scenario_objects]
    assert names == ["ego", "vru0"]
    ego = by_stem[stem].ego
    box = parsed.entities.scenario_objects[0].entityobject.boundingbox
    assert (box.boundingbox.length, box.boundingbox.width) == (ego.length_m, ego.width_m)


def test_opendrive_road_is_the_world_frame(exported):
    folder, by_stem = exported
    for stem, layout in (("paper-pedestrian-crossing", "straight"), ("paper-motorcyclist-crossing", "intersection")):
        scenario = by_stem[stem]
        root = etree.parse(str(folder / f"{stem}.xodr")).getroot()
        half = road_half_length_m(scenario)
        first = root.find("road[@id='1']/planView/geometry")
        assert (float(first.get("x")), float(first.get("y")), float(first.get("hdg"))) == (-half, 0.0, 0.0)
        widths = {float(w.get("a")) for w in root.iter("width")}
        assert widths == {scenario.road.lane_width_m}
        arms = [r for r in root.iter("road") if r.get("junction") == "-1"]
        assert len(arms) == (1 if layout == "straight" else 4)
        assert (root.find("junction") is not None) == (layout == "intersection")
    for stem, scenario in by_stem.items():  # the road reaches every start position
        assert road_half_length_m(scenario) > abs(scenario.ego.start.x_m), stem


# ----------------------------------------------------------------------------------------------- triggers


def test_catalogue_triggers_are_the_ones_vrusim_uses(exported):
    """Each catalogue VRU starts on the same condition: ego travelled distance (rear axle) or time."""
    folder, by_stem = exported
    checked = 0
    for test in DAY_TESTS:
        scenario = by_stem[file_stem(test.test_id)]
        doc = Xosc(folder / f"{file_stem(test.test_id)}.xosc")
        for index, vru in enumerate(scenario.vrus):
            start = doc.event(f"vru{index}_start")
            if start is None:
                continue
            trigger = vru.trigger
            if trigger.ego_route_m is not None:
                condition = start.find(".//EntityCondition/TraveledDistanceCondition")
                assert start.find(".//TriggeringEntities/EntityRef").get("entityRef") == "ego"
                assert doc.value(condition.get("value")) == trigger.ego_route_m
            else:
                condition = start.find(".//SimulationTimeCondition")
                assert doc.value(condition.get("value")) == trigger.at_time_s
            checked += 1
            brake = doc.event(f"vru{index}_brake")
            if vru.brake is not None:
                delay = brake.find(".//Condition").get("delay")
                assert doc.value(delay) == vru.brake.after_trigger_s
    assert checked > 100


def _with_trigger(trigger: dict) -> Scenario:
    base = load_scenario(ROOT / "scenarios" / "paper" / "pedestrian_crossing.yaml")
    data = base.model_dump()
    data["planner"] = {"name": "none"}
    data["vrus"][0]["trigger"] = trigger
    return Scenario.model_validate(data)


@pytest.mark.parametrize(
    "trigger",
    [
        {"ego_distance_m": 25.0, "point": {"x_m": 18.0, "y_m": -1.75}},
        {"ego_time_to_arrival_s": 2.5, "point": {"x_m": 18.0, "y_m": -1.75}},
    ],
    ids=["ego-distance", "time-to-arrival"],
)
def test_distance_triggers_become_the_ego_travel_where_vrusim_fires_them(trigger):
    """A non-reacting run: the VRU starts in the step where the ego's station passes the exported value."""
    scenario = _with_trigger(trigger)
    doc_export = build_export(scenario)
    with tempfile.TemporaryDirectory() as folder:
        doc = Xosc(doc_export.write(Path(folder))[0])
    station = doc.value(doc.event("vru0_start").find(".//TraveledDistanceCondition").get("value"))
    assert station == trigger_station_m(scenario.ego, scenario.vrus[0].trigger, 200.0)
    run = simulate([scenario], trace=True)
    ego_station = run.trace["ego_station_m"][:, 0]
    moving = np.flatnonzero(run.trace["vru_speed_mps"][:, 0, 0] > 0.0)[0]  # row i: state at (i + 1) dt
    # the trigger was judged at the start of that step, on the ego state of the row before
    assert ego_station[moving - 2] < station <= ego_station[moving - 1] + 1e-9


# ----------------------------------------------------------------------------------------------- CLI


def test_cli_exports_a_yaml_file(tmp_path):
    out = tmp_path / "out"
    result = invoke("export", YAML_FILES[0], "--format", "openscenario", "--out", out)
    assert result.exit_code == 0, result.output
    stem = file_stem(load_scenario(YAML_FILES[0]).name)
    assert sorted(p.name for p in out.iterdir()) == [f"{stem}.xodr", f"{stem}.xosc"]
    assert "Exported 1 scenario as openscenario: 2 files in" in " ".join(result.output.split())


def test_cli_exports_a_catalogue_id_and_a_prefix(tmp_path):
    result = invoke("export", "CPNA-25/20kph/day", "--format", "OpenSCENARIO", "--out", tmp_path)
    assert result.exit_code == 0, result.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["CPNA-25_20kph_day.xodr", "CPNA-25_20kph_day.xosc"]
    result = invoke("export", "cpna-75", "--format", "openscenario", "--out", tmp_path / "prefix", "--night")
    assert result.exit_code == 0, result.output
    expected = select(protocol="2023", codes=["CPNA-75"], night=True)
    assert len(list((tmp_path / "prefix").glob("*.xosc"))) == len(expected)


def test_cli_commonroad_exports_simulated_runs_that_load(tmp_path):
    from commonroad.common.file_reader import CommonRoadFileReader

    result = invoke("export", "CPNA-25", "--format", "commonroad", "--out", tmp_path)
    assert result.exit_code == 0, result.output
    expected = select(protocol="2023", codes=["CPNA-25"])
    files = sorted(tmp_path.glob("*.xml"))
    assert len(files) == len(expected) > 1
    said = " ".join(result.output.split())
    assert f"Exported {len(expected)} scenarios as commonroad: {len(expected)} files in" in said
    scenario, _ = CommonRoadFileReader(str(files[0])).open()
    assert len(scenario.dynamic_obstacles) == 2  # the ego and the pedestrian


@pytest.mark.parametrize(
    ("args", "names"),
    [
        (["CPNA-25/20kph/day", "--format", "xml"], ["--format", "xml"]),
        (["CPNA-25/20kph/dai"], ["SOURCE", "CPNA-25/20kph/day"]),
        (["CPXX"], ["SOURCE", "did you mean CPNA"]),
        (["missing.yaml"], ["missing.yaml"]),
        ([str(YAML_FILES[0]), "--night"], ["--night: only for catalogue tests"]),  # was ignored
        (["paper:pedestrian", "--night"], ["--night: only for catalogue tests"]),
    ],
    ids=["format", "unknown-id", "unknown-code", "missing-file", "night-file", "night-bundled"],
)
def test_cli_errors_write_nothing(tmp_path, args, names):
    out = tmp_path / "out"
    if "--format" not in args:
        args = [*args, "--format", "openscenario"]
    result = invoke("export", *args, "--out", out)
    if "--format" in names:  # typer's own message for a bad choice, also exit code 2
        assert result.exit_code == 2 and "Invalid value" in result.output
    else:
        assert_user_error(result, *names)
    assert not out.exists()


def test_cli_bad_yaml_and_out_file_are_user_errors(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("name: [unclosed\n")
    assert_user_error(invoke("export", bad, "--format", "openscenario", "--out", tmp_path / "o"), "bad.yaml", "YAML")
    assert not (tmp_path / "o").exists()
    target = tmp_path / "taken"
    target.write_text("keep")
    assert_user_error(invoke("export", YAML_FILES[0], "--format", "openscenario", "--out", target), "--out")
    assert target.read_text() == "keep"
