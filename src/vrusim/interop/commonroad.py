"""CommonRoad export of a simulated run: `export_commonroad(scenario, out_dir)` (docs/interop.md, "CommonRoad").

One traced closed-loop run of the scenario (the planner's reaction included) becomes one CommonRoad 2020a XML
file: the road as a lanelet network, the ego, every VRU and every parked car as obstacles with their simulated
trajectories, and a planning problem for the ego. Written through commonroad-io's `CommonRoadFileWriter`.
"""

from __future__ import annotations

import contextlib
import io
import logging
import os
import re
from collections.abc import Callable, Iterator
from pathlib import Path

from vrusim.extras import extra

with extra("export"):
    from commonroad.common.common_scenario import FileInformation, ScenarioID
    from commonroad.common.file_writer import CommonRoadFileWriter, OverwriteExistingFile
    from commonroad.common.util import FileFormat
    from commonroad.planning.planning_problem import PlanningProblemSet
    from commonroad.scenario.scenario import Scenario as CrScenario
    from commonroad.scenario.scenario import Tag

from vrusim.errors import UserInputError
from vrusim.interop.commonroad_agents import (
    ego_obstacle,
    ego_turn_centre_line,
    junction_half_size_m,
    map_extent_m,
    parked_obstacles,
    planning_problem,
    vru_obstacles,
)
from vrusim.interop.commonroad_lanelets import road_network
from vrusim.io.atomic import write_atomically, write_together
from vrusim.scenario.schema import Scenario
from vrusim.version import __version__
from vrusim.viz.recording import Recording, record

DECIMALS = 10
"""Decimal places written for every number (commonroad-io truncates; its default of 4 would cost 1e-4 m)."""

MAP_MARGIN_M = 10.0
"""Lanes reach this far past the ego's run and route end when those go beyond the drawn road, m."""

AUTHOR = "vrusim"
AFFILIATION = "vrusim: open-source closed-loop VRU safety simulator"


def export_commonroad(scenario: Scenario, out_dir: Path, ego_as_obstacle: bool = True) -> list[Path]:
    """Simulate `scenario` once (traced) and write `<file_stem(name)>.xml` (CommonRoad 2020a) into `out_dir`.

    With `ego_as_obstacle` the ego appears both as the planning problem and as dynamic obstacle id 1 (its
    simulated run); planners that solve the problem drop that obstacle. Returns the written path. A missing
    or unwritable `out_dir` raises UserInputError.
    """
    return export_commonroad_all([scenario], out_dir, ego_as_obstacle)


def export_commonroad_all(scenarios: list[Scenario], out_dir: Path, ego_as_obstacle: bool = True) -> list[Path]:
    """`export_commonroad` for many scenarios: simulated as one traced batch per planner, every file built in
    memory, then all written together (atomically: on any failure none is written). Two scenarios whose file
    names collide raise UserInputError before anything runs."""
    out_dir = Path(out_dir)
    if not out_dir.is_dir():
        raise UserInputError(f"--out: {out_dir} is not an existing folder")
    if not os.access(out_dir, os.W_OK | os.X_OK):
        raise UserInputError(f"--out: cannot write into {out_dir} (permission denied)")
    paths = [out_dir / f"{file_stem(scenario.name)}.xml" for scenario in scenarios]
    if len(set(paths)) != len(paths):
        raise UserInputError("SOURCE: two scenarios would be written to the same CommonRoad file name")
    recordings = _record_by_planner(scenarios)
    targets = [
        (path, _xml_writer(recording, ego_as_obstacle), "CommonRoad file")
        for path, recording in zip(paths, recordings, strict=True)
    ]
    return write_together(targets)


def write_recording(recording: Recording, out_dir: Path, ego_as_obstacle: bool = True) -> Path:
    """Write one recorded run as `<out_dir>/<file_stem(name)>.xml`, atomically; return the path."""
    path = Path(out_dir) / f"{file_stem(recording.scenario.name)}.xml"
    return write_atomically(path, _xml_writer(recording, ego_as_obstacle), "CommonRoad file")


def _record_by_planner(scenarios: list[Scenario]) -> list[Recording]:
    """Traced runs of the scenarios, in order; one batch per planner name (a batch runs one planner)."""
    recordings: list[Recording | None] = [None] * len(scenarios)
    for name in dict.fromkeys(s.planner.name for s in scenarios):
        indices = [i for i, s in enumerate(scenarios) if s.planner.name == name]
        for i, recording in zip(indices, record([scenarios[i] for i in indices]), strict=True):
            recordings[i] = recording
    return [r for r in recordings if r is not None]


def _xml_writer(recording: Recording, ego_as_obstacle: bool) -> Callable[[Path], None]:
    """A function writing the run's CommonRoad XML to a given path (the document is built now)."""
    scenario, problems = build_commonroad(recording, ego_as_obstacle)
    metadata = (AUTHOR, AFFILIATION, _source(recording.scenario), _tags(recording.scenario))

    def write(path: Path) -> None:
        # commonroad-io keeps the decimal precision in a module global, set by the writer's constructor
        writer = CommonRoadFileWriter(
            scenario, problems, *metadata, decimal_precision=DECIMALS, file_format=FileFormat.XML
        )
        with _quiet_writer():
            writer.write_to_file(str(path), OverwriteExistingFile.ALWAYS)

    return write


def build_commonroad(recording: Recording, ego_as_obstacle: bool = True) -> tuple[CrScenario, PlanningProblemSet]:
    """The CommonRoad scenario and planning problem set of one recorded run.

    Ids: ego 1, VRUs 2.., parked cars next, then the planning problem, then lanelets and the intersection.
    """
    source = recording.scenario
    cr = CrScenario(dt=source.sim.dt_s, scenario_id=scenario_id(source.name))
    cr.file_information = FileInformation(author=AUTHOR, affiliation=AFFILIATION, source=_source(source))
    vru_first = 2
    parked_first = vru_first + len(source.vrus)
    problem_id = parked_first + len(source.obstacles)
    junction = junction_half_size_m(source)
    extent_x, extent_y = map_extent_m(recording, MAP_MARGIN_M)
    extent_x, extent_y = max(extent_x, junction + MAP_MARGIN_M), max(extent_y, junction + MAP_MARGIN_M)
    turn = ego_turn_centre_line(source.ego)
    network, _ = road_network(source.road, extent_x, extent_y, junction, problem_id + 1, turn)
    cr.add_objects(network)
    if ego_as_obstacle:
        cr.add_objects(ego_obstacle(recording, 1))
    cr.add_objects(vru_obstacles(recording, vru_first))
    cr.add_objects(parked_obstacles(source.obstacles, parked_first))
    problems = PlanningProblemSet([planning_problem(recording, problem_id, source.road.lane_width_m)])
    return cr, problems


def scenario_id(name: str) -> ScenarioID:
    """`ZAM_<Name>-1_1_T-1`: Zamunda (CommonRoad's country for made-up maps), the name's letters and digits in
    CamelCase (CommonRoad's map names are [a-zA-Z0-9]+), map 1, configuration 1, trajectory-predicted 1."""
    words = re.findall(r"[A-Za-z0-9]+", name)
    map_name = "".join(word[0].upper() + word[1:] for word in words) or "Vrusim"
    return ScenarioID(
        country_id="ZAM", map_name=map_name, map_id=1, configuration_id=1, obstacle_behavior="T", prediction_id=1
    )


def file_stem(name: str) -> str:
    """A file name stem for a scenario name: runs of characters other than letters, digits, '.', '_' and '-'
    become '_' (`CPNA-25/20kph/day` → `CPNA-25_20kph_day`)."""
    return re.sub(r"[^A-Za-z0-9._-]+", "_", name).strip("._") or "scenario"


@contextlib.contextmanager
def _quiet_writer() -> Iterator[None]:
    """Silence commonroad-io's writer: it prints "Replace file ..." for the (existing) temporary file and logs a
    warning per intersection reference that the 2020a format names `successorsLeft` etc."""
    writer_log = logging.getLogger("commonroad.common.writer.file_writer_xml")
    level = writer_log.level
    writer_log.setLevel(logging.ERROR)
    try:
        with contextlib.redirect_stdout(io.StringIO()):
            yield
    finally:
        writer_log.setLevel(level)


def _source(scenario: Scenario) -> str:
    return (
        f"vrusim {__version__}: one simulated closed-loop run of scenario '{scenario.name}' "
        f"(planner {scenario.planner.name}, V2X {'on' if scenario.v2x.enabled else 'off'})"
    )


def _tags(scenario: Scenario) -> set[Tag]:
    tags = {Tag.SIMULATED, Tag.URBAN, Tag.TWO_LANE}
    if scenario.road.layout == "intersection":
        tags.add(Tag.INTERSECTION)
    tags.add({"straight": Tag.LANE_FOLLOWING, "left": Tag.TURN_LEFT, "right": Tag.TURN_RIGHT}[scenario.ego.route.kind])
    return tags
