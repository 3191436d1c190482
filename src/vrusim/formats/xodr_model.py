"""An OpenDRIVE road network as plain frozen dataclasses: roads, reference-line geometries, lanes, junctions.

Only what places things on the ground plane is kept (ASAM OpenDRIVE 1.6 / 1.8): the plan view, the lane
offset, lane sections with lane widths and road mark types (for drawing), road links and junction
connections. Lengths in m, angles in rad (counter-clockwise from +x), curvatures in 1/m; stations `s` along a
road's reference line, `t` to its left.
`line` is the line of the file an item was read from (0: not read from a file), for error messages.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Straight:
    """`<line>`: a straight reference line."""


@dataclass(frozen=True)
class Arc:
    """`<arc>`: constant curvature (1/m; positive turns left)."""

    curvature_per_m: float


@dataclass(frozen=True)
class Spiral:
    """`<spiral>`: an Euler spiral (clothoid), curvature linear in s from `curv_start_per_m` to `curv_end_per_m`."""

    curv_start_per_m: float
    curv_end_per_m: float


@dataclass(frozen=True)
class Poly3:
    """`<poly3>` (deprecated since 1.6): local v(u) = a + b u + c u^2 + d u^3 (u, v in m), s is arc length."""

    a: float
    b: float
    c: float
    d: float


@dataclass(frozen=True)
class ParamPoly3:
    """`<paramPoly3>`: local u(p), v(p) cubics; p in [0, length] (`normalized` False: pRange="arcLength") or [0, 1]."""

    u: tuple[float, float, float, float]
    v: tuple[float, float, float, float]
    normalized: bool


Shape = Straight | Arc | Spiral | Poly3 | ParamPoly3


@dataclass(frozen=True)
class Geometry:
    """One `<geometry>` of a plan view: from station `s_m` for `length_m`, starting at (x_m, y_m) heading `hdg_rad`."""

    s_m: float
    x_m: float
    y_m: float
    hdg_rad: float
    length_m: float
    shape: Shape
    line: int = 0


@dataclass(frozen=True)
class Cubic:
    """a + b ds + c ds^2 + d ds^3 from station `s_m` (m; `sOffset` of a width record: from the section start)."""

    s_m: float
    a: float
    b: float
    c: float
    d: float


@dataclass(frozen=True)
class RoadMark:
    """A `<roadMark>`: the mark on a lane's outer border from `s_offset_m` (from the section start), e.g. "solid"."""

    s_offset_m: float
    type: str
    line: int = 0


@dataclass(frozen=True)
class Lane:
    """A `<lane>`: id (0 centre, > 0 left, < 0 right of the reference line), type, width records and road marks;
    the lane ids its `<link>` names as predecessors and successors (on the linked road; empty: none given)."""

    id: int
    type: str
    widths: tuple[Cubic, ...]
    line: int = 0
    predecessors: tuple[int, ...] = ()
    successors: tuple[int, ...] = ()
    marks: tuple[RoadMark, ...] = ()


@dataclass(frozen=True)
class LaneSection:
    """A `<laneSection>` from station `s_m`: lanes ordered outward (left 1, 2, ...; right -1, -2, ...)."""

    s_m: float
    left: tuple[Lane, ...]
    right: tuple[Lane, ...]
    line: int = 0
    centre_marks: tuple[RoadMark, ...] = ()
    """The road marks of the centre lane (on the border at the lane offset)."""


@dataclass(frozen=True)
class Link:
    """A road's `<predecessor>` or `<successor>`: a road (with the contact point of that road) or a junction."""

    element_type: str  # "road" | "junction"
    element_id: str
    contact_point: str | None  # "start" | "end"; None for a junction


@dataclass(frozen=True)
class Road:
    """A `<road>`: id, length (m), junction id ("-1": none), links, plan view, lane offset and lane sections."""

    id: str
    length_m: float
    junction: str
    rule: str  # "RHT" | "LHT": the side traffic keeps to
    predecessor: Link | None
    successor: Link | None
    geometries: tuple[Geometry, ...]
    lane_offsets: tuple[Cubic, ...]
    sections: tuple[LaneSection, ...]
    line: int = 0


@dataclass(frozen=True)
class Connection:
    """A junction `<connection>`: from `incoming_road` over `connecting_road` (entered at `contact_point`)."""

    id: str
    incoming_road: str
    connecting_road: str
    contact_point: str  # "start" | "end" of the connecting road
    lane_links: tuple[tuple[int, int], ...]  # (from lane of the incoming road, to lane of the connecting road)


@dataclass(frozen=True)
class Junction:
    """A `<junction>` and its connections."""

    id: str
    name: str
    connections: tuple[Connection, ...]


@dataclass(frozen=True)
class Network:
    """A whole `.xodr` file: its revision, roads and junctions by id."""

    rev_major: int
    rev_minor: int
    roads: dict[str, Road]
    junctions: dict[str, Junction]
    source: str = ""  # the file it was read from, for error messages
