"""Euro NCAP protocol knowledge shared by every edition, as plain data: the record types of a scenario table
(`NcapScenario`, `Cell`), targets, turning paths, obstructions.

Each edition's scenario table lives in `ncap/editions/` (`2023`: AEB VRU v4.5.1; `2026`: Crash Avoidance FC26 /
LSC26); `ncap/build.py` turns an entry into executable Scenarios. A value inferred rather than read in the texts
is listed in the entry's `unverified` tuple, shown by `vrusim list` and in docs/euroncap.md. Speeds in km/h (as
the protocol writes them), lengths in m.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

from vrusim.scenario.vru_types import VruType

KPH = 1.0 / 3.6
"""m/s per km/h."""


@dataclass(frozen=True)
class Dummy:
    """A protocol target: box dimensions (length along its heading, width) and reference points.

    `ref_from_rear_m` is the reference point's distance from the rear of the box along its heading, per use.
    """

    code: str
    vru_type: VruType
    length_m: float
    width_m: float
    height_m: float
    ref_from_rear_m: dict[str, float]
    source: str
    unverified: tuple[str, ...] = ()


DUMMIES: dict[str, Dummy] = {
    "EPTa": Dummy(
        "EPTa",
        VruType.PEDESTRIAN,
        0.60,
        0.50,
        1.80,
        # hip 0.36 m behind the front of the 0.60 m box (V23 VRU_collisionPointOffset); back for longitudinal
        {"crossing": 0.24, "longitudinal": 0.0},
        "ISO 19206-2:2018 via V23 catalogs",
        ("virtual-box dimensions (protocol figures are images)",),
    ),
    "EPTc": Dummy(
        "EPTc",
        VruType.PEDESTRIAN,
        0.711,
        0.298,
        1.154,
        {"crossing": 0.711 - 0.396, "longitudinal": 0.0},
        "ISO 19206-2:2018 via V23 catalogs",
        ("virtual-box dimensions (protocol figures are images)",),
    ),
    "EBTa": Dummy(
        "EBTa",
        VruType.CYCLIST,
        1.89,
        0.50,
        1.20,
        # box from -0.34 to +1.55 m about the rear axle; crank 0.62 m ahead of the rear axle; front of front wheel
        {"crossing": 0.34 + 0.62, "longitudinal": 0.0, "turning": 1.89},
        "ISO 19206-4:2020 via V23 catalogs",
        ("height 1.20 m looks like the bicycle only",),
    ),
    "EMT": Dummy(
        "EMT",
        VruType.MOTORCYCLIST,
        2.08,
        0.79,
        1.06,
        # front of the front wheel for turning and crossing (FC26 §1.4.1.3), rear of the rear wheel ahead
        {"turning": 2.08, "longitudinal": 0.0, "crossing": 2.08},
        "ISO 19206-5 via V23 catalogs",
        ("height 1.06 m",),
    ),
    "ESC": Dummy(  # vrusim extension: the paper's e-scooter footprint (r = 1.0 m) as a 2 m box
        "ESC",
        VruType.E_SCOOTER,
        2.0,
        2.0,
        1.8,
        {"crossing": 1.0, "longitudinal": 0.0, "turning": 2.0},
        "paper Sec. IV-A footprint radius 1.0 m (vrusim extension; Euro NCAP has no e-scooter target)",
    ),
}


@dataclass(frozen=True)
class TurnPath:
    """Turning path: clothoid R1 → R2 over angle α, arc R2 over β, clothoid back (FC26 §1.2.4, V23)."""

    entry_radius_m: float
    radius_m: float
    clothoid_angle_deg: float
    arc_angle_deg: float


TURN_PATHS: dict[tuple[str, float], TurnPath] = {
    ("farside", 10.0): TurnPath(1500.0, 9.00, 20.62, 48.75),
    ("farside", 15.0): TurnPath(1500.0, 11.75, 20.93, 48.14),
    ("farside", 20.0): TurnPath(1500.0, 14.75, 21.79, 46.42),
    ("nearside", 10.0): TurnPath(1500.0, 8.00, 22.85, 44.30),
    # FC26 §1.2.4 "20 and 25 km/h to Farside"; §3.2.2: "The 25 km/h turn ... is conducted in the 20 km/h path"
    ("farside", 25.0): TurnPath(1500.0, 14.75, 21.79, 46.42),
}
"""Keyed by (turn side, VUT speed in km/h). Farside = left turn, nearside = right turn (left-hand drive)."""

Layout = Literal[
    "crossing",
    "longitudinal",
    "turning",
    "reverse",
    "rear",
    "oncoming",
    "standstill_start",
    "pedal_misapplication",
    "dooring",
]
"""2026 low-speed layouts (LSC26; the builder does not support them yet): standstill_start — the VUT starts
from standstill (SfS) towards a crossing / oncoming target; pedal_misapplication — a creeping VUT gets full
accelerator pedal towards a standing child (CPMFC); dooring — a cyclist passes the parked VUT whose driver
door is operated (CBDA)."""
Function = Literal["AEB", "FCW", "avoidance", "ACPE", "dooring"]
"""2026 low speed: ACPE = accelerator control for pedal error (CPMFC), dooring = CBDA door response."""


@dataclass(frozen=True)
class Cell:
    """One test of a scenario's grid: VUT speed, and what else varies (target, impact location, EMT speed)."""

    vut_speed_kph: float
    variant: str = ""
    target: str | None = None
    impact_location: float | None = None
    target_speed_kph: float | None = None
    range: Literal["standard", "extended", "robustness"] = "standard"
    """What the cell belongs to (2026: the standard or extended range of FC26 §3, the official calculator's
    EXTENDED_RANGE_CELLS, or a robustness layer). 2023 cells are all "standard"."""
    function: Function | None = None
    """The cell's function when it differs from its scenario's (2026: FCW rows inside an AEB grid)."""
    gap_m: float | None = None
    """2026 low-speed grids: the distance the grid varies (CBNAO SfS d, CPMRCm / CBDA rear gap), m."""
    row_label: str = ""
    """2026 low-speed grids: the protocol's label of the cell's grid row where it is not the VUT speed
    ("1.50 m", CPMFC's "d1" / "d2"); empty elsewhere."""


@dataclass(frozen=True)
class NcapScenario:
    """One protocol scenario with its test grid.

    Geometry by layout (world frame: VUT approaches along +x in the lane at y = -lane/2; see docs/euroncap.md):
    crossing — target crosses the VUT path from `side` starting `lateral_offset_m` from the VUT path
    centreline, accelerating over `accel_distance_m`; longitudinal / rear — target ahead in the VUT lane,
    `steady_distance_m` at constant speed before impact (0 speed: stationary); turning — VUT turns to `turn`,
    target moves on a line `target_line_m` from the approach road's centre line, parallel to it, in the VUT's
    original direction if `moves_with_vut`, starting `start_to_impact_m` before the impact (or already at
    speed when tagged "flying"); oncoming — target comes towards the turning VUT in the opposite lane at
    constant speed; reverse — VUT reverses towards a target crossing its rear path (starting
    `start_to_impact_m` away) or standing in it.

    `impact_location` is a fraction of the VUT's width on its front (rear when reversing; 0 = right edge of
    the vehicle, ISO 8855) or, when `impact_side` is "left" / "right", a fraction of its length along that
    side measured from the rear (1 = front).
    """

    code: str
    group: Literal["pedestrian", "cyclist", "motorcyclist", "escooter"]
    description: str
    layout: Layout
    target: str
    target_speed_kph: float
    cells: tuple[Cell, ...]
    impact_location: float = 0.5
    function: Function = "AEB"
    lighting: tuple[str, ...] = ("day",)
    side: Literal["nearside", "farside", "ahead", "oncoming"] = "nearside"
    lateral_offset_m: float = 0.0
    start_to_impact_m: float = 0.0
    impact_side: Literal["front", "left", "right"] = "front"
    accel_distance_m: float = 0.0
    steady_distance_m: float = 0.0
    turn: Literal["farside", "nearside"] | None = None
    target_line_m: float = 0.0
    moves_with_vut: bool = True
    obstruction: Literal["CPNCO", "CBNA", "CBNAO", "CBFA", "CMCscp"] | None = None
    headway_s: float = 0.0
    target_decel_mps2: float = 0.0
    extension: bool = False
    official: str = ""
    """2026: the official calculator's scenario name; "{lighting}" in it stands for the test's lighting
    (e.g. "CPNA {lighting}" -> "CPNA day"). Empty: not scored by the calculator (2023, extensions)."""
    unverified: tuple[str, ...] = ()
    sources: str = ""
    tags: tuple[str, ...] = field(default=())
    """Engine / builder features the scenario needs that vrusim does not have yet (2026 low-speed tests:
    a VUT starting from standstill, pedal misapplication, a door). Empty: `ncap/build.py` can build it."""


def speeds(first: float, last: float, step: float = 5.0) -> tuple[Cell, ...]:
    """Cells for VUT speeds first..last (km/h) inclusive."""
    count = round((last - first) / step) + 1
    return tuple(Cell(first + i * step) for i in range(count))


LANE_WIDTH_M = 3.5
"""Lane width of the straight road and the junction arms (FC26: main approach lane 3.5 m)."""

OBSTRUCTION_CARS: dict[str, tuple[float, float]] = {
    "small car": (4.316, 1.79),
    "SUV": (4.418, 1.82),
}
"""(length, width) of the parked obstruction vehicles, m (V23 values inside the FC26 Appendix B ranges)."""


@dataclass(frozen=True)
class Obstruction:
    """A row of parked cars (first listed nearest the conflict), parallel to the VUT path or to the side road.

    along_vut: cars parallel to the VUT path on the nearside, `clearance_m` clear of the VUT's side, the first
    car's front `first_offset_m` before the target's path edge. Otherwise: cars parallel to the target's path
    on the VUT's side of it, `clearance_m` clear of the target, the row ending `first_offset_m` from the VUT
    lane centre line.
    """

    cars: tuple[str, ...]
    along_vut: bool
    clearance_m: float
    first_offset_m: float
    gap_m: float
    source: str


OBSTRUCTIONS: dict[str, Obstruction] = {
    "CPNCO": Obstruction(("small car", "SUV"), True, 1.0, 1.0, 1.0, "V23 CPNCO (I = J = 1 m); FC26 §3.2.3.1"),
    "CBNA": Obstruction(("SUV", "small car"), False, 1.0, 17.0, 0.2, "V23 CBNA (row ends at D = 17 m)"),
    "CBNAO": Obstruction(("SUV", "small car"), False, 4.8, 3.55, 0.2, "V23 CBNAO (I = 3.55 m, J = 4.8 m)"),
    "CBFA": Obstruction(
        ("SUV", "small car"),
        False,
        1.0,
        22.0,
        0.2,
        "FC26 §3.2.3.2 Fig. 3-27 (SUV nearest the junction, 0.1-0.3 m gap) with Appendix B cars; V23 CBFA: SUV rear"
        " axle at CP - 22 m - rear overhang, turned 180°, so its junction-side end is at the 22 m steady-state"
        " point (vectorgrp #15 closed: no sign error); distances from the figure UNVERIFIED (image only)",
    ),
    # 2026, CMCscp standard range only (nearside approach; the farside row, 5.5 m off, needs builder support)
    "CMCscp": Obstruction(
        ("SUV", "small car", "small car"),
        True,
        2.0 - 0.9,
        1.0,
        1.0,
        "FC26 §3.1.3.2: 3 parked cars 1 m apart, large first, 2 m from the VUT trajectory (clearance = 2.0 m "
        "minus half our 1.8 m VUT); first car 1.0 m before the EMT path and the third car's type UNVERIFIED",
    ),
}
"""Parked obstruction rows by scenario family."""
