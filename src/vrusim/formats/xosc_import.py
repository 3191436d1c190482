"""Import an OpenSCENARIO 1.x file (`.xosc`) of the subset vrusim's export writes as a vrusim `Scenario`.

`read_xosc(path)` reads the file safely (`xml_file`: size limit, no DTD or entities, line numbers), resolves its
parameters (`xosc_document`) and its catalog locations (`xosc_catalogs`), reads the road network its
`<RoadNetwork><LogicFile>` names (relative to the .xosc, inside its folder; `xodr_reader`), the entities
(`xosc_entities`) and the storyboard (`xosc_storyboard`), and builds the scenario (`xosc_scenario`,
`xosc_route_fit`, `xosc_road`). Anything outside the subset is a UserInputError naming the file, the line and
the element (docs/openscenario_import.md). The planner, sensor, V2X and simulation step are not in the file: the
scenario gets vrusim's defaults for them.
`import_xosc` also returns the warnings: elements ignored because they do not change the motion (`xosc_notes`; more
of them with `lenient`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from vrusim.errors import UserInputError
from vrusim.formats.xml_file import Element, read_xml_file, shown
from vrusim.formats.xodr_model import Network
from vrusim.formats.xodr_reader import read_xodr
from vrusim.formats.xosc_catalogs import Catalogs
from vrusim.formats.xosc_distribution import DISTRIBUTION_TAG, is_distribution
from vrusim.formats.xosc_document import XoscDocument
from vrusim.formats.xosc_entities import read_entities
from vrusim.formats.xosc_notes import ImportNotes
from vrusim.formats.xosc_road import drawn_road_fields, road_fields
from vrusim.formats.xosc_scenario import ScenarioBuilder
from vrusim.formats.xosc_storyboard import read_storyboard
from vrusim.scenario.loading import scenario_from_mapping
from vrusim.scenario.schema import Scenario

XOSC_SUFFIX = ".xosc"
_TOP_LEVEL = {
    "FileHeader",
    "ParameterDeclarations",
    "VariableDeclarations",
    "CatalogLocations",
    "RoadNetwork",
    "Entities",
    "Storyboard",
}


def _header(doc: XoscDocument, root: Element, path: Path) -> tuple[str, str]:
    """(scenario name, description): the header's `vrusim_scenario` property or the file stem; its description."""
    header = doc.child(root, "FileHeader")
    doc.children(header, {"Properties", "License"})
    revision = (doc.raw(header, "revMajor"), doc.raw(header, "revMinor"))
    if revision[0] != "1":
        raise doc.fail(header, f"OpenSCENARIO {revision[0]}.{revision[1]} is not supported (1.x is)")
    name = doc.properties(header).get("vrusim_scenario") or path.stem
    description = doc.raw(header, "description", "")
    prefix = f"{name}: "
    return name, description.removeprefix(prefix).split(" (exported by vrusim")[0]


def _road_network(doc: XoscDocument, root: Element, path: Path) -> Network:
    network = doc.child(root, "RoadNetwork")
    doc.children(network, {"LogicFile", "SceneGraphFile", "TrafficSignals", "UsedArea"})
    for child in network.children:
        if child.tag != "LogicFile" and child.tag != "SceneGraphFile":
            raise doc.unsupported(child, "RoadNetwork")
    logic = network.first("LogicFile")
    if logic is None:
        raise doc.fail(network, "has no <LogicFile>: vrusim needs the OpenDRIVE road (.xodr)")
    name = doc.text(logic, "filepath")
    doc.confined_path(logic, "filepath", path.parent, name)
    road_file = path.parent / name  # as written, for messages
    if not road_file.is_file():
        raise doc.fail(logic, f"names {shown(name)}, which is not a file next to the .xosc")
    return read_xodr(road_file)


@dataclass(frozen=True)
class XoscImport:
    """An imported file: the scenario and the warnings (ignored elements, with their lines)."""

    scenario: Scenario
    warnings: tuple[str, ...]


def parse_root(
    root: Element,
    path: Path,
    parameters: dict[str, str] | None = None,
    notes: ImportNotes | None = None,
    drawing: bool = True,
) -> Scenario:
    """The scenario of an OpenSCENARIO document (root element), read from `path`; `parameters` (name -> value
    text) replace the values of the file's parameter declarations; ignored elements go to `notes`. `drawing`:
    the road keeps the network's drawn lines and surfaces (`xosc_road.drawn_road_fields`)."""
    doc = XoscDocument(str(path), parameters)
    if root.tag != "OpenSCENARIO":
        raise doc.fail(root, "is not an OpenSCENARIO document (expected <OpenSCENARIO>)")
    if is_distribution(root):
        raise doc.fail(
            root.first(DISTRIBUTION_TAG) or root,
            "makes this a parameter distribution, not a scenario: run its variants with "
            f"`vrusim sweep {path} --out DIR`",
        )
    doc.children(root, _TOP_LEVEL)
    name, description = _header(doc, root, path)
    doc.declare(root.first("ParameterDeclarations"))
    doc.declare_variables(doc.optional(root, "VariableDeclarations"))
    doc.catalogs = Catalogs.read(doc, doc.optional(root, "CatalogLocations"), path)
    network = _road_network(doc, root, path)
    entities = read_entities(doc, doc.child(root, "Entities"))
    story = read_storyboard(doc, doc.child(root, "Storyboard"), network, {e.name for e in entities}, notes)
    data = ScenarioBuilder(doc, entities, story).mapping()
    road = drawn_road_fields(network, notes.warnings if notes else None) if drawing else road_fields(network)
    data = {"name": name, "description": description, "road": road} | data
    return scenario_from_mapping(data, str(path))


def read_xosc_root(path: str | Path) -> tuple[Element, Path]:
    """The root element of the OpenSCENARIO file `path` (read safely) and the path."""
    path = Path(path)
    if path.suffix.lower() != XOSC_SUFFIX:
        raise UserInputError(f"{path}: expected an OpenSCENARIO file ({XOSC_SUFFIX})")
    return read_xml_file(path, "OpenSCENARIO"), path


def import_xosc(path: str | Path, lenient: bool = False, parameters: dict[str, str] | None = None) -> XoscImport:
    """The scenario of the OpenSCENARIO file `path` and the import's warnings. `lenient`: unsupported elements that
    do not change the motion (weather, road condition, controllers) are warnings instead of errors; `parameters`
    (name -> value text) replace the values its parameter declarations give."""
    root, path = read_xosc_root(path)
    notes = ImportNotes(lenient=lenient)
    scenario = parse_root(root, path, parameters, notes)
    return XoscImport(scenario, tuple(f"{path}: {warning}" for warning in notes.warnings))


def read_xosc(path: str | Path, parameters: dict[str, str] | None = None, lenient: bool = False) -> Scenario:
    """The vrusim scenario of the OpenSCENARIO file `path` (its road file next to it, as its LogicFile says);
    `parameters` replace declared values, `lenient` as `import_xosc`."""
    return import_xosc(path, lenient, parameters).scenario


read_scenario_file = read_xosc
"""The reader `vrusim.sources.load_scenario_file` calls for a `.xosc` SOURCE."""
