"""OpenSCENARIO catalogs (`vrusim.formats.xosc_catalogs`): entities, a maneuver and a trajectory moved into catalogs
import as the inline file does; parameter assignments reach the right field; bad catalogs are one clear error."""

from __future__ import annotations

import shutil
import time
from pathlib import Path

import pytest

from cli_helpers import invoke
from vrusim.errors import UserInputError
from vrusim.formats.xml_file import Element
from vrusim.formats.xosc_catalogs import _Directory, _read_directory
from vrusim.formats.xosc_document import XoscDocument
from vrusim.formats.xosc_import import read_xosc
from xosc_helpers import edited, refused

DATA = Path(__file__).parent / "data" / "xosc" / "catalogs"
"""inline.xosc (an export of CPNA-25/20kph/day) and catalogs.xosc: the same with the ego, the pedestrian, the
ego's maneuver and its trajectory in catalogs under Catalogs/; the ego's length assigned from $EgoLength."""


@pytest.fixture
def copy(tmp_path: Path) -> Path:
    """A copy of the data folder: catalogs.xosc in it, to edit."""
    shutil.copytree(DATA, tmp_path / "case")
    return tmp_path / "case" / "catalogs.xosc"


def _line(path: Path, text: str) -> str:
    """`line N` of the first line of `path` containing `text`."""
    lines = path.read_text().splitlines()
    return f"line {next(n for n, line in enumerate(lines, 1) if text in line)}"


def test_catalog_references_import_as_the_inline_file():
    assert read_xosc(DATA / "catalogs.xosc") == read_xosc(DATA / "inline.xosc")


def test_an_assignment_changes_the_entry_and_only_its_field(copy):
    base = read_xosc(copy)
    changed = read_xosc(
        edited(
            copy,
            'name="EgoLength" parameterType="double" value="4.5"',
            'name="EgoLength" parameterType="double" value="5.1"',
        )
    )
    assert changed.ego.length_m == pytest.approx(5.1)
    assert (
        changed.ego.model_copy(update={"length_m": base.ego.length_m, "rear_overhang_m": base.ego.rear_overhang_m})
        == base.ego
    )


def test_a_scenario_parameter_overrides_the_assignment_value(copy):
    assert read_xosc(copy, {"EgoLength": "4.2"}).ego.length_m == pytest.approx(4.2)


def test_without_an_assignment_the_entry_default_applies(copy):
    edited(copy, '<ParameterAssignment parameterRef="Length" value="$EgoLength"/>', "")
    assert read_xosc(copy).ego.length_m == pytest.approx(4.0)


def test_a_second_assignment_reaches_its_field(copy):
    edited(
        copy,
        '<ParameterAssignment parameterRef="Length" value="$EgoLength"/>',
        '<ParameterAssignment parameterRef="Length" value="$EgoLength"/>'
        '<ParameterAssignment parameterRef="MaxDecel" value="7.5"/>',
    )
    assert read_xosc(copy).ego.max_decel_mps2 == pytest.approx(7.5)


def test_an_entry_does_not_see_the_scenario_parameters(copy):
    vehicles = copy.parent / "Catalogs" / "Vehicles" / "vehicles.xosc"
    edited(vehicles, 'maxAcceleration="2.0"', 'maxAcceleration="$EgoInitialSpeed_mps"')
    refused(copy, "vehicles.xosc", "EgoInitialSpeed_mps", "not declared")


def test_an_assignment_to_an_undeclared_parameter_isrefused(copy):
    edited(copy, 'parameterRef="Length"', 'parameterRef="Width"')
    refused(
        copy,
        "catalogs.xosc",
        "<ParameterAssignment>",
        _line(copy, 'parameterRef="Width"'),
        "'Width'",
        "declares no such parameter",
    )


def test_an_unknown_catalog_isrefused(copy):
    edited(copy, 'catalogName="People"', 'catalogName="Persons"')
    refused(copy, "<CatalogReference>", _line(copy, "Persons"), "'Persons'", "no such catalog")


def test_an_unknown_entry_isrefused(copy):
    edited(copy, 'entryName="adult"', 'entryName="child"')
    refused(copy, "<CatalogReference>", _line(copy, "child"), "'child'", "no such entry")


def test_an_entry_of_the_wrong_kind_isrefused(copy):
    routes = copy.parent / "Catalogs" / "Trajectories" / "trajectories.xosc"
    edited(routes, '<Catalog name="Routes">', '<Catalog name="Routes"><Vehicle name="car"/>')
    maneuvers = copy.parent / "Catalogs" / "Maneuvers" / "maneuvers.xosc"
    edited(maneuvers, 'entryName="ego_route"', 'entryName="car"')
    refused(copy, "maneuvers.xosc", "<CatalogReference>", "'car' is a <Vehicle>", "expected <Trajectory>")


def test_a_directory_leading_out_of_the_folder_isrefused(copy):
    edited(copy, 'path="Catalogs/Vehicles"', 'path="Catalogs/../../Vehicles"')
    refused(copy, "<Directory>", _line(copy, "../../Vehicles"), "leads outside")


def test_a_missing_directory_isrefused(copy):
    edited(copy, 'path="Catalogs/Vehicles"', 'path="Catalogs/Lorries"')
    refused(copy, "<Directory>", _line(copy, "Lorries"), "not a directory")


def test_a_catalog_file_with_a_dtd_isrefused(copy):
    people = copy.parent / "Catalogs" / "Pedestrians" / "pedestrians.xosc"
    edited(people, "<OpenSCENARIO>", '<!DOCTYPE x [<!ENTITY a "b">]>\n<OpenSCENARIO>')
    refused(
        copy, "<CatalogReference>", _line(copy, 'catalogName="People"'), "pedestrians.xosc", "document type declaration"
    )


def test_a_catalog_file_linked_from_outside_the_directory_isrefused(copy, tmp_path):
    outside = tmp_path / "elsewhere.xosc"
    shutil.copy(copy.parent / "Catalogs" / "Pedestrians" / "pedestrians.xosc", outside)
    (copy.parent / "Catalogs" / "Pedestrians" / "pedestrians.xosc").unlink()
    (copy.parent / "Catalogs" / "Pedestrians" / "linked.xosc").symlink_to(outside)
    refused(copy, "<CatalogReference>", "linked.xosc", "outside the catalog directory")


def test_reading_a_catalog_is_linear_in_its_entries(tmp_path):
    """`names.count(name)` per entry took minutes for 60,000 entries; 15,000 took seconds, now a tenth of a second
    with the XML parse; a duplicate name is still reported at its first entry."""
    folder = tmp_path / "Vehicles"
    folder.mkdir()
    entries = "".join(f'<Vehicle name="v{i}"/>\n' for i in range(15_000))
    catalog = folder / "cars.xosc"
    catalog.write_text(f'<OpenSCENARIO>\n<Catalog name="Cars">\n{entries}</Catalog></OpenSCENARIO>')
    directory = _Directory(folder, Element("Directory", {}, 1))
    started = time.perf_counter()
    found = _read_directory(XoscDocument("x.xosc"), directory)
    assert time.perf_counter() - started < 1.0
    assert len(found["Cars"].entries) == 15_000 and found["Cars"].entries["v14999"].line == 15_002
    catalog.write_text(catalog.read_text().replace('"v7"', '"v9"'))
    with pytest.raises(UserInputError, match=r"cars\.xosc: line 10: <Vehicle> name 'v9' is used twice"):
        _read_directory(XoscDocument("x.xosc"), directory)


def test_a_reference_without_catalog_locations_isrefused(copy):
    text = copy.read_text()
    start, end = text.index("<CatalogLocations>"), text.index("</CatalogLocations>") + len("</CatalogLocations>")
    copy.write_text(text[:start] + "<CatalogLocations/>" + text[end:])
    refused(copy, "<CatalogReference>", "no such catalog")


def test_a_controller_catalog_isrefused(copy):
    edited(
        copy, "<VehicleCatalog>", '<ControllerCatalog><Directory path="Catalogs"/></ControllerCatalog><VehicleCatalog>'
    )
    refused(copy, "<ControllerCatalog>", "not supported")


TOO_LONG = "a/" * 2100
"""A name the OS refuses (ENAMETOOLONG): a file name inside a .xosc is looked up, never trusted."""


@pytest.mark.parametrize(
    ("folder", "name", "old", "element"),
    [
        ("catalogs", "inline.xosc", 'filepath="road.xodr"', "<LogicFile> filepath"),
        ("catalogs", "catalogs.xosc", 'path="Catalogs/Vehicles"', "<Directory> path"),
        ("distribution", "cpna_10x3.xosc", 'filepath="cpna.xosc"', "<ScenarioFile> filepath"),
    ],
)
def test_a_file_name_the_os_cannot_use_is_a_user_error(tmp_path, folder, name, old, element):
    """Found by the fuzz campaign: `Path.is_file()` raised OSError (File name too long) for such a name."""
    shutil.copytree(DATA.parent / folder, tmp_path / "case")
    attribute = old.split("=")[0]
    path = edited(tmp_path / "case" / name, old, f'{attribute}="{TOO_LONG}"')
    command = "sweep" if folder == "distribution" else "import"
    result = invoke(command, str(path), "--out", str(tmp_path / "out.yaml" if command == "import" else tmp_path / "o"))
    assert result.exit_code == 2, result.output
    message = " ".join(result.output.split())
    assert "Traceback" not in message and element in message and "cannot use" in message, message


@pytest.mark.parametrize(
    ("folder", "name", "old", "element"),
    [
        ("catalogs", "inline.xosc", 'filepath="road.xodr"', "<LogicFile> filepath"),
        ("distribution", "cpna_10x3.xosc", 'filepath="cpna.xosc"', "<ScenarioFile> filepath"),
    ],
)
@pytest.mark.parametrize("target", ["../outside/FILE", "ABSOLUTE", "/etc/passwd", "link"])
def test_a_file_named_outside_the_folder_is_refused_before_it_is_read(tmp_path, folder, name, old, element, target):
    """A `<LogicFile>` or `<ScenarioFile>` could name any file on disk (`/etc/passwd` was parsed, its parse error
    telling that it exists); now confined to the folder of the file naming it, as catalog directories are."""
    shutil.copytree(DATA.parent / folder, tmp_path / "case")
    wanted = old.split('"')[1]
    outside = tmp_path / "outside" / wanted
    outside.parent.mkdir()
    shutil.copy(tmp_path / "case" / wanted, outside)
    (tmp_path / "case" / "link").symlink_to(outside)
    value = {"../outside/FILE": f"../outside/{wanted}", "ABSOLUTE": str(outside)}.get(target, target)
    path = edited(tmp_path / "case" / name, old, f'filepath="{value}"')
    command = "sweep" if folder == "distribution" else "import"
    result = invoke(command, str(path), "--out", str(tmp_path / "out.yaml" if command == "import" else tmp_path / "o"))
    assert result.exit_code == 2, result.output
    message = " ".join(result.output.split())
    assert "Traceback" not in message and f"{element} '{value[:40]}" in message, message
    assert "leads outside the folder of the" in message and "line " in message, message
    assert not (tmp_path / "out.yaml").exists() and not (tmp_path / "o").exists()
