"""OpenSCENARIO catalogs: `<CatalogLocations>` directories, catalog files, and `<CatalogReference>` resolution.

Each location (`VehicleCatalog`, `PedestrianCatalog`, `MiscObjectCatalog`, `ManeuverCatalog`, `RouteCatalog`,
`TrajectoryCatalog`) names one `<Directory path>`, relative to the .xosc, that must lie inside the .xosc's folder
(no absolute path, no `..` leading out of it). The directory's `*.xosc` files (at most `MAX_FILES`, not its
sub-folders) are read safely (`xml_file`) when a reference first needs them; files that resolve outside the
directory are refused, files without a `<Catalog>` are skipped. A reference names a catalog (`catalogName`) and
an entry (`entryName`); the entry is the element the readers then read as if it were inline.

Parameters (ASAM OpenSCENARIO 1.x, "parameters in catalogs"): an entry sees only its own `<ParameterDeclarations>`,
not the scenario's; those are its defaults, and the reference's `<ParameterAssignment>`s replace them. An
assigned `value` is read where the reference is, so it may be a scenario parameter (`value="$EgoLength"`). An
assignment to a parameter the entry does not declare is an error.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

from vrusim.errors import UserInputError
from vrusim.formats.xml_file import Element, read_xml_file, shown
from vrusim.formats.xosc_document import XoscDocument

LOCATIONS = (
    "VehicleCatalog",
    "PedestrianCatalog",
    "MiscObjectCatalog",
    "ManeuverCatalog",
    "RouteCatalog",
    "TrajectoryCatalog",
)
ENTITY_LOCATIONS = ("VehicleCatalog", "PedestrianCatalog", "MiscObjectCatalog")
MAX_FILES = 64
"""Catalog files read per directory, at most."""


@dataclass(frozen=True)
class CatalogEntry:
    """A resolved reference: the entry's scope (its file, its parameters) and its element (no declarations)."""

    doc: XoscDocument
    element: Element


@dataclass(frozen=True)
class _Catalog:
    """One `<Catalog>`: its file, its element and its entries by name."""

    path: Path
    element: Element
    entries: dict[str, Element]


@dataclass
class _Directory:
    path: Path
    element: Element
    catalogs: dict[str, _Catalog] | None = None


@dataclass
class Catalogs:
    """The catalog locations of one scenario file; catalog files are read once, when first referenced."""

    directories: dict[str, _Directory] = field(default_factory=dict)

    @classmethod
    def read(cls, doc: XoscDocument, locations: Element | None, base: Path) -> Catalogs:
        """The `<CatalogLocations>` of the file at `base` (its folder); every directory checked now."""
        catalogs = cls()
        if locations is None:
            return catalogs
        folder = base.parent.resolve()
        for location in doc.children(locations, set(LOCATIONS) | {"ControllerCatalog", "EnvironmentCatalog"}):
            if location.tag not in LOCATIONS:
                raise doc.unsupported(location, locations.tag)
            if location.tag in catalogs.directories:
                raise doc.fail(location, "may appear once inside <CatalogLocations>")
            doc.children(location, {"Directory"})
            directory = doc.child(location, "Directory")
            name = doc.text(directory, "path")
            path = doc.confined_path(directory, "path", folder, name)
            if not path.is_dir():
                raise doc.fail(directory, f"path {shown(name)} is not a directory next to the .xosc")
            catalogs.directories[location.tag] = _Directory(path, directory)
        return catalogs

    def entry(self, doc: XoscDocument, reference: Element, locations: tuple[str, ...], tags: set[str]) -> CatalogEntry:
        """The entry `reference` (a `<CatalogReference>` read in `doc`) names, in a catalog of `locations`,
        which must be one of `tags`, with its parameters assigned."""
        doc.children(reference, {"ParameterAssignments"})
        catalog_name, entry_name = doc.text(reference, "catalogName"), doc.text(reference, "entryName")
        hit = next((h for loc in locations if (h := self._catalogs(doc, reference, loc).get(catalog_name))), None)
        if hit is None:
            where = ", ".join(f"<{location}>" for location in locations)
            raise doc.fail(reference, f"catalogName {shown(catalog_name)}: no such catalog in {where}")
        path, element = hit.path, hit.entries.get(entry_name)
        if element is None:
            raise doc.fail(reference, f"entryName {shown(entry_name)}: catalog {shown(catalog_name)} has no such entry")
        if element.tag not in tags:
            expected = ", ".join(f"<{tag}>" for tag in sorted(tags))
            raise doc.fail(reference, f"entry {shown(entry_name)} is a <{element.tag}> ({path}), expected {expected}")
        declarations = element.first("ParameterDeclarations")
        scope = XoscDocument(str(path), _assignments(doc, reference, declarations, entry_name))
        scope.catalogs = self
        scope.declare(declarations)
        children = [child for child in element.children if child.tag != "ParameterDeclarations"]
        return CatalogEntry(scope, Element(element.tag, element.attrib, element.line, children))

    def _catalogs(self, doc: XoscDocument, reference: Element, location: str) -> dict[str, _Catalog]:
        directory = self.directories.get(location)
        if directory is None:
            return {}
        if directory.catalogs is None:
            try:
                directory.catalogs = _read_directory(doc, directory)
            except UserInputError as error:
                raise doc.fail(reference, f"catalog: {error}") from None
        return directory.catalogs


def _read_directory(doc: XoscDocument, directory: _Directory) -> dict[str, _Catalog]:
    """Catalog name -> catalog of the catalog files in `directory` (entries indexed by name: linear in them)."""
    files = sorted(p for p in directory.path.iterdir() if p.suffix.lower() == ".xosc" and not p.is_dir())
    if len(files) > MAX_FILES:
        raise doc.fail(directory.element, f"has {len(files)} .xosc files; at most {MAX_FILES} are read")
    found: dict[str, _Catalog] = {}
    for path in files:
        if not path.resolve().is_relative_to(directory.path):
            raise UserInputError(f"{path}: leads outside the catalog directory; refused")
        root = read_xml_file(path, "OpenSCENARIO catalog")
        catalog = root.first("Catalog") if root.tag == "OpenSCENARIO" else None
        if catalog is None:
            continue
        name = doc.raw(catalog, "name")
        if name in found:
            raise UserInputError(f"{path}: line {catalog.line}: catalog {shown(name)} is also in {found[name].path}")
        found[name] = _Catalog(path, catalog, _entries(path, catalog))
    return found


def _entries(path: Path, catalog: Element) -> dict[str, Element]:
    """The entries of `catalog` (read from `path`) by name; one without a name, or a name used twice (reported at
    its first entry), is an error."""
    counts = Counter(entry.attrib.get("name") for entry in catalog.children)
    for entry in catalog.children:
        entry_name = entry.attrib.get("name")
        if entry_name is None or counts[entry_name] > 1:
            problem = "has no name" if entry_name is None else f"name {shown(entry_name)} is used twice"
            raise UserInputError(f"{path}: line {entry.line}: <{entry.tag}> {problem}")
    return {entry.attrib["name"]: entry for entry in catalog.children}


def _assignments(doc: XoscDocument, reference: Element, declarations: Element | None, entry: str) -> dict[str, str]:
    """Parameter name -> value text of the reference's `<ParameterAssignments>` (values read in `doc`)."""
    declared = {d.attrib.get("name") for d in (declarations.children if declarations is not None else [])}
    holder = doc.optional(reference, "ParameterAssignments")
    values: dict[str, str] = {}
    for assignment in doc.children(holder, {"ParameterAssignment"}) if holder is not None else []:
        doc.children(assignment, set())
        name = doc.raw(assignment, "parameterRef")
        if name not in declared:
            raise doc.fail(assignment, f"parameterRef {shown(name)}: entry {shown(entry)} declares no such parameter")
        if name in values:
            raise doc.fail(assignment, f"parameterRef {shown(name)} is assigned twice")
        values[name] = doc.text(assignment, "value")
    return values


def catalog_entry(doc: XoscDocument, reference: Element, locations: tuple[str, ...], tags: set[str]) -> CatalogEntry:
    """The catalog entry `<CatalogReference>` `reference` names (one of `tags`, in a catalog of `locations`)."""
    if doc.catalogs is None:
        raise doc.fail(reference, "(a catalog reference) is not supported here; write the element inline")
    return doc.catalogs.entry(doc, reference, locations, tags)
