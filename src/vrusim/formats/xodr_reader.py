"""Read an OpenDRIVE `.xodr` file into a `xodr_model.Network`, refusing anything malformed or unsupported.

Reading is safe (`xml_file`: size limit, no DTD or entities). Every element that shapes the ground plan is
checked: a missing or non-numeric attribute, an unknown geometry kind, a lane `<border>`, a one-sided lane
section, lane ids that do not count 1, 2, ... outward, a link to a road that does not exist: each is a
UserInputError naming the file, the line and the element (docs/opendrive_import.md). A `<roadMark>`'s sOffset
and type are read for drawing (the same checks). Elements that do not shape the plan (elevation, road mark
details, objects, signals, user data) are skipped.
"""

from __future__ import annotations

from pathlib import Path

from vrusim.errors import UserInputError
from vrusim.formats.xml_file import Element, attribute_number, parse_xml, read_xml_file, shown
from vrusim.formats.xodr_model import (
    Arc,
    Connection,
    Cubic,
    Geometry,
    Junction,
    Lane,
    LaneSection,
    Link,
    Network,
    ParamPoly3,
    Poly3,
    Road,
    RoadMark,
    Shape,
    Spiral,
    Straight,
)
from vrusim.limits import check_limit

_SHAPES = ("line", "arc", "spiral", "poly3", "paramPoly3")
ROAD_MARK_TYPES = (
    "none",
    "solid",
    "broken",
    "solid solid",
    "solid broken",
    "broken solid",
    "broken broken",
    "botts dots",
    "grass",
    "curb",
    "custom",
    "edge",
)
"""`<roadMark type>` values of ASAM OpenDRIVE 1.6 / 1.8 (e_roadMarkType)."""


class _Reader:
    """Turns elements into model objects; `fail` names the file, line and element."""

    def __init__(self, source: str) -> None:
        self.source = source

    def fail(self, element: Element, message: str) -> UserInputError:
        return UserInputError(f"{self.source}: line {element.line}: <{element.tag}> {message}")

    def text(self, element: Element, name: str, default: str | None = None) -> str:
        value = element.attrib.get(name, default)
        if value is None:
            raise self.fail(element, f"has no attribute {name!r}")
        return value

    def number(self, element: Element, name: str, default: float | None = None) -> float:
        if name not in element.attrib and default is not None:
            return default
        return attribute_number(self.fail, self.source, element, name, self.text(element, name))

    def integer(self, element: Element, name: str) -> int:
        value = self.number(element, name)
        if not value.is_integer():
            raise self.fail(element, f"attribute {name}: expected a whole number, got {shown(element.attrib[name])}")
        return int(value)

    def choice(self, element: Element, name: str, options: tuple[str, ...], default: str | None = None) -> str:
        value = self.text(element, name, default)
        if value not in options:
            raise self.fail(element, f"attribute {name}: expected one of {', '.join(options)}, got {shown(value)}")
        return value

    def cubic(self, element: Element, station: str) -> Cubic:
        return Cubic(*(self.number(element, name) for name in (station, "a", "b", "c", "d")))

    def only(self, parent: Element, tag: str) -> Element:
        found = parent.all(tag)
        if len(found) != 1:
            raise self.fail(parent, f"needs exactly one <{tag}>, has {len(found)}")
        return found[0]

    # ------------------------------------------------------------------------------------------------ roads

    def shape(self, geometry: Element) -> Shape:
        kinds = [child for child in geometry.children if child.tag in _SHAPES]
        unknown = [child for child in geometry.children if child.tag not in _SHAPES and child.tag != "userData"]
        if unknown:
            raise self.fail(unknown[0], f"is not a supported geometry ({', '.join(_SHAPES)})")
        if len(kinds) != 1:
            raise self.fail(geometry, f"needs exactly one of {', '.join(_SHAPES)}, has {len(kinds)}")
        kind = kinds[0]
        if kind.tag == "line":
            return Straight()
        if kind.tag == "arc":
            return Arc(self.number(kind, "curvature"))
        if kind.tag == "spiral":
            return Spiral(self.number(kind, "curvStart"), self.number(kind, "curvEnd"))
        if kind.tag == "poly3":
            return Poly3(*(self.number(kind, name) for name in "abcd"))
        u = tuple(self.number(kind, f"{c}U") for c in "abcd")
        v = tuple(self.number(kind, f"{c}V") for c in "abcd")
        p_range = self.choice(kind, "pRange", ("arcLength", "normalized"), "normalized")
        return ParamPoly3(u, v, p_range == "normalized")  # type: ignore[arg-type]

    def length(self, element: Element) -> float:
        """A `length` attribute: >= 0 and within the `length_m` limit (roads are sampled along it)."""
        length = self.number(element, "length")
        if length < 0:
            raise self.fail(element, f"attribute length: must be >= 0, got {length:g}")
        check_limit("length_m", length, f"{self.source}: line {element.line}: <{element.tag}> attribute length")
        return length

    def geometry(self, element: Element) -> Geometry:
        values = [self.number(element, name) for name in ("s", "x", "y", "hdg")]
        return Geometry(*values, self.length(element), shape=self.shape(element), line=element.line)

    def link(self, element: Element | None) -> Link | None:
        if element is None:
            return None
        kind = self.choice(element, "elementType", ("road", "junction"))
        contact = self.choice(element, "contactPoint", ("start", "end")) if kind == "road" else None
        return Link(kind, self.text(element, "elementId"), contact)

    def marks(self, lane: Element) -> tuple[RoadMark, ...]:
        """A lane's `<roadMark>`s: sOffset and type (drawing only; their geometry details are skipped)."""
        elements = lane.all("roadMark")
        marks = tuple(
            RoadMark(self.number(mark, "sOffset"), self.choice(mark, "type", ROAD_MARK_TYPES), mark.line)
            for mark in elements
        )
        _ascending(self, elements, [mark.s_offset_m for mark in marks], "sOffset")
        return marks

    def lane(self, element: Element) -> Lane:
        if element.first("border") is not None:
            raise self.fail(element.first("border"), "is not supported (lane widths only)")  # type: ignore[arg-type]
        widths = tuple(self.cubic(width, "sOffset") for width in element.all("width"))
        _ascending(self, element.all("width"), [w.s_m for w in widths], "sOffset")
        link = element.first("link")
        links = [
            [self.integer(e, "id") for e in link.all(tag)] if link is not None else []
            for tag in ("predecessor", "successor")
        ]
        lane_type = element.attrib.get("type", "none")
        return Lane(
            self.integer(element, "id"), lane_type, widths, element.line, tuple(links[0]), tuple(links[1]),
            self.marks(element),
        )  # fmt: skip

    def side(self, section: Element, tag: str, sign: int) -> tuple[Lane, ...]:
        holder = section.first(tag)
        if holder is None:
            return ()
        lanes = sorted((self.lane(element) for element in holder.all("lane")), key=lambda lane: abs(lane.id))
        expected = [sign * n for n in range(1, len(lanes) + 1)]
        if [lane.id for lane in lanes] != expected:
            raise self.fail(
                holder, f"lane ids must be {', '.join(map(str, expected))}, got {[lane.id for lane in lanes]}"
            )
        return tuple(lanes)

    def section(self, element: Element) -> LaneSection:
        if element.attrib.get("singleSide", "false") == "true":
            raise self.fail(element, "singleSide='true' is not supported")
        centre = self.only(element, "center")
        if [lane.attrib.get("id") for lane in centre.all("lane")] != ["0"]:
            raise self.fail(centre, "needs exactly one <lane> with id 0")
        return LaneSection(
            self.number(element, "s"),
            self.side(element, "left", 1),
            self.side(element, "right", -1),
            element.line,
            self.marks(centre.all("lane")[0]),
        )

    def road(self, element: Element) -> Road:
        length = self.length(element)
        plan = self.only(element, "planView")
        geometries = tuple(self.geometry(child) for child in plan.all("geometry"))
        if not geometries:
            raise self.fail(plan, "has no <geometry>")
        _ascending(self, plan.all("geometry"), [g.s_m for g in geometries], "s")
        lanes = self.only(element, "lanes")
        offsets = tuple(self.cubic(child, "s") for child in lanes.all("laneOffset"))
        _ascending(self, lanes.all("laneOffset"), [o.s_m for o in offsets], "s")
        sections = tuple(self.section(child) for child in lanes.all("laneSection"))
        if not sections:
            raise self.fail(lanes, "has no <laneSection>")
        _ascending(self, lanes.all("laneSection"), [section.s_m for section in sections], "s")
        links = element.first("link")
        return Road(
            id=self.text(element, "id"),
            length_m=length,
            junction=element.attrib.get("junction", "-1"),
            rule=self.choice(element, "rule", ("RHT", "LHT"), "RHT"),
            predecessor=self.link(links.first("predecessor") if links is not None else None),
            successor=self.link(links.first("successor") if links is not None else None),
            geometries=geometries,
            lane_offsets=offsets,
            sections=sections,
            line=element.line,
        )

    # -------------------------------------------------------------------------------------------- junctions

    def connection(self, element: Element) -> Connection:
        links = tuple((self.integer(link, "from"), self.integer(link, "to")) for link in element.all("laneLink"))
        return Connection(
            id=self.text(element, "id"),
            incoming_road=self.text(element, "incomingRoad"),
            connecting_road=self.text(element, "connectingRoad"),
            contact_point=self.choice(element, "contactPoint", ("start", "end")),
            lane_links=links,
        )

    def junction(self, element: Element) -> Junction:
        connections = tuple(self.connection(child) for child in element.all("connection"))
        return Junction(self.text(element, "id"), element.attrib.get("name", ""), connections)

    def network(self, root: Element) -> Network:
        if root.tag != "OpenDRIVE":
            raise self.fail(root, "is not an OpenDRIVE document (the root element must be <OpenDRIVE>)")
        header = root.first("header")
        major = self.integer(header, "revMajor") if header is not None and "revMajor" in header.attrib else 1
        minor = self.integer(header, "revMinor") if header is not None and "revMinor" in header.attrib else 0
        roads: dict[str, Road] = {}
        for element in root.all("road"):
            road = self.road(element)
            if road.id in roads:
                raise self.fail(element, f"id {shown(road.id)} is used by another road (line {roads[road.id].line})")
            roads[road.id] = road
        junctions: dict[str, Junction] = {}
        for element in root.all("junction"):
            junction = self.junction(element)
            if junction.id in junctions:
                raise self.fail(element, f"id {shown(junction.id)} is used by another junction")
            junctions[junction.id] = junction
        self.check_references(root, roads, junctions)
        return Network(major, minor, roads, junctions, self.source)

    def check_references(self, root: Element, roads: dict[str, Road], junctions: dict[str, Junction]) -> None:
        """Every road link and junction connection names a road or junction of the file."""
        for element in root.all("road"):
            road = roads[element.attrib["id"]]
            for link in (road.predecessor, road.successor):
                if link is not None and link.element_id not in (roads if link.element_type == "road" else junctions):
                    raise self.fail(
                        element, f"links to {link.element_type} {shown(link.element_id)}, which does not exist"
                    )
            if road.junction != "-1" and road.junction not in junctions:
                raise self.fail(element, f"attribute junction: no junction {shown(road.junction)}")
        for element in root.all("junction"):
            for child, connection in zip(
                element.all("connection"), junctions[element.attrib["id"]].connections, strict=True
            ):
                for name in (connection.incoming_road, connection.connecting_road):
                    if name not in roads:
                        raise self.fail(child, f"names road {shown(name)}, which does not exist")


def _ascending(reader: _Reader, elements: list[Element], stations: list[float], name: str) -> None:
    """Records of one kind must come in order of their station attribute."""
    for previous, (element, station) in zip(stations, zip(elements[1:], stations[1:], strict=True), strict=False):
        if station < previous:
            raise reader.fail(element, f"attribute {name}: {station:g} is before the previous record's {previous:g}")


def read_xodr(path: Path) -> Network:
    """The road network of the OpenDRIVE file `path`; anything malformed or unsupported is a UserInputError."""
    reader = _Reader(str(path))
    return reader.network(read_xml_file(Path(path), "OpenDRIVE"))


def parse_xodr(text: str, source: str = "<OpenDRIVE text>") -> Network:
    """The road network of OpenDRIVE XML `text` (`source` names it in messages); checks as `read_xodr`."""
    check_limit("input_file_bytes", len(text.encode()), source)
    return _Reader(source).network(parse_xml(text, source))
