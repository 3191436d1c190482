"""Euro NCAP AEB VRU protocol (v4.5.1, rating years 2023–2025) as plain data: targets, turning paths, scenarios.

The single place for protocol knowledge; `ncap_build.py` turns an entry into executable Scenarios. Values come
from our spec `reference/euroncap_vru.md` (source keys V23 = Vector's OpenSCENARIO encoding of v4.5.1, FC26 =
the 2026 successor protocol, Q451 = literal v4.5.1 quotes). A value the spec marks UNVERIFIED is listed in the
entry's `unverified` tuple, shown by `vrusim list` and in docs/euroncap.md. Speeds in km/h (as the protocol
writes them), lengths in m.
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
        {"turning": 2.08, "longitudinal": 0.0},
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
}
"""Keyed by (turn side, VUT speed in km/h). Farside = left turn, nearside = right turn (left-hand drive)."""

Layout = Literal["crossing", "longitudinal", "turning", "reverse", "rear", "oncoming"]
Function = Literal["AEB", "FCW", "avoidance"]


@dataclass(frozen=True)
class Cell:
    """One test of a scenario's grid: VUT speed, and what else varies (target, impact location, EMT speed)."""

    vut_speed_kph: float
    variant: str = ""
    target: str | None = None
    impact_location: float | None = None
    target_speed_kph: float | None = None


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
    obstruction: Literal["CPNCO", "CBNA", "CBNAO", "CBFA"] | None = None
    headway_s: float = 0.0
    target_decel_mps2: float = 0.0
    extension: bool = False
    unverified: tuple[str, ...] = ()
    sources: str = ""
    tags: tuple[str, ...] = field(default=())


def speeds(first: float, last: float, step: float = 5.0) -> tuple[Cell, ...]:
    """Cells for VUT speeds first..last (km/h) inclusive."""
    count = round((last - first) / step) + 1
    return tuple(Cell(first + i * step) for i in range(count))


SCENARIOS: tuple[NcapScenario, ...] = (
    # ---- pedestrian --------------------------------------------------------------------------------------
    NcapScenario(
        "CPFA-50",
        "pedestrian",
        "adult running from the farside",
        "crossing",
        "EPTa",
        8.0,
        speeds(10, 60),
        side="farside",
        lateral_offset_m=6.0,
        accel_distance_m=1.5,
        lighting=("day", "night"),
        unverified=("night variant",),
        sources="V23 CPFA-50; Q451 (10-60); FC26 (8 km/h)",
    ),
    NcapScenario(
        "CPNA-25",
        "pedestrian",
        "adult walking from the nearside, 25 %",
        "crossing",
        "EPTa",
        5.0,
        speeds(10, 60),
        impact_location=0.25,
        lateral_offset_m=4.0,
        accel_distance_m=1.0,
        lighting=("day", "night"),
        sources="V23; Q451; RES (day/night)",
    ),
    NcapScenario(
        "CPNA-75",
        "pedestrian",
        "adult walking from the nearside, 75 %",
        "crossing",
        "EPTa",
        5.0,
        speeds(10, 60),
        impact_location=0.75,
        lateral_offset_m=4.0,
        accel_distance_m=1.0,
        lighting=("day", "night"),
        sources="V23; Q451; RES (day/night)",
    ),
    NcapScenario(
        "CPNCO-50",
        "pedestrian",
        "child running from behind two parked cars",
        "crossing",
        "EPTc",
        5.0,
        speeds(10, 60),
        lateral_offset_m=4.0,
        accel_distance_m=1.0,
        obstruction="CPNCO",
        lighting=("day", "night"),
        sources="V23 CPNCO; FC26 §3.2.3.1 (car order); MW (day/night)",
    ),
    NcapScenario(
        "CPLA-50",
        "pedestrian",
        "adult walking ahead in the lane, 50 %",
        "longitudinal",
        "EPTa",
        5.0,
        speeds(20, 60),
        side="ahead",
        accel_distance_m=1.0,
        steady_distance_m=10.0,
        lighting=("day", "night"),
        sources="V23 CBLA base; Q451 (20-60); RES (day/night)",
    ),
    NcapScenario(
        "CPLA-25",
        "pedestrian",
        "adult walking ahead in the lane, 25 %",
        "longitudinal",
        "EPTa",
        5.0,
        speeds(50, 80),
        impact_location=0.25,
        function="FCW",
        side="ahead",
        accel_distance_m=1.0,
        steady_distance_m=10.0,
        lighting=("day", "night"),
        unverified=("FCW-only vs FCW-or-AEB wording", "night variant"),
        sources="V23; Q451 (50-80); FC26; RES (CPLA day/night)",
    ),
    NcapScenario(
        "CPTAfs",
        "pedestrian",
        "farside turn, pedestrian walking the same direction",
        "turning",
        "EPTa",
        5.0,
        (Cell(10.0), Cell(15.0), Cell(20.0)),
        function="avoidance",
        turn="farside",
        target_line_m=9.5,
        start_to_impact_m=9.5,
        accel_distance_m=2.0,
        sources="V23 CPTA; Q451 (10, 15, 20)",
    ),
    NcapScenario(
        "CPTAfo",
        "pedestrian",
        "farside turn, pedestrian walking the opposite direction",
        "turning",
        "EPTa",
        5.0,
        (Cell(10.0), Cell(15.0), Cell(20.0)),
        function="avoidance",
        turn="farside",
        target_line_m=9.5,
        start_to_impact_m=6.0,
        accel_distance_m=2.0,
        moves_with_vut=False,
        sources="V23 CPTA; Q451",
    ),
    NcapScenario(
        "CPTAns",
        "pedestrian",
        "nearside turn, pedestrian walking the same direction",
        "turning",
        "EPTa",
        5.0,
        (Cell(10.0),),
        function="avoidance",
        turn="nearside",
        target_line_m=9.5,
        start_to_impact_m=6.0,
        accel_distance_m=2.0,
        sources="V23 CPTAns-50_10kph",
    ),
    NcapScenario(
        "CPTAno",
        "pedestrian",
        "nearside turn, pedestrian walking the opposite direction",
        "turning",
        "EPTa",
        5.0,
        (Cell(10.0),),
        function="avoidance",
        turn="nearside",
        target_line_m=9.5,
        start_to_impact_m=9.5,
        accel_distance_m=2.0,
        moves_with_vut=False,
        sources="V23 CPTAno-50_10kph",
    ),
    NcapScenario(
        "CPRA-Cm",
        "pedestrian",
        "reversing towards a pedestrian crossing behind",
        "reverse",
        "EPTa",
        5.0,
        (Cell(4.0, "adult", "EPTa"), Cell(8.0, "child", "EPTc")),
        start_to_impact_m=4.0,
        accel_distance_m=1.5,
        function="avoidance",
        unverified=("VUT start 10 m before the collision point (V23: not in the protocol)",),
        sources="V23 CPRA_Cm_Variation; Q451 (4, 8)",
    ),
    NcapScenario(
        "CPRA-Cs",
        "pedestrian",
        "reversing towards a standing pedestrian",
        "reverse",
        "EPTa",
        0.0,
        (
            Cell(4.0, "IL50-adult", "EPTa", 0.50),
            Cell(8.0, "IL50-child", "EPTc", 0.50),
            Cell(4.0, "IL25-child", "EPTc", 0.25),
            Cell(8.0, "IL25-adult", "EPTa", 0.25),
            Cell(4.0, "IL75-child", "EPTc", 0.75),
            Cell(8.0, "IL75-adult", "EPTa", 0.75),
        ),
        function="avoidance",
        unverified=("VUT start 10 m before the collision point (V23: not in the protocol)",),
        sources="V23 CPRA_Cs_Variation (6 pairs)",
    ),
    # ---- cyclist -----------------------------------------------------------------------------------------
    NcapScenario(
        "CBNA-50",
        "cyclist",
        "cyclist from a nearside side road, past parked cars",
        "crossing",
        "EBTa",
        15.0,
        speeds(10, 60),
        lateral_offset_m=24.0,
        accel_distance_m=7.0,
        obstruction="CBNA",
        unverified=("start ≈ 7 m behind the steady-state point (protocol: < 8 m)",),
        sources="V23 CBNA",
        tags=("junction",),
    ),
    NcapScenario(
        "CBNAO-50",
        "cyclist",
        "cyclist from the nearside emerging from behind an obstruction",
        "crossing",
        "EBTa",
        10.0,
        speeds(10, 60),
        lateral_offset_m=11.5,
        accel_distance_m=7.0,
        obstruction="CBNAO",
        unverified=("start ≈ 7 m behind the steady-state point",),
        sources="V23 CBNAO",
        tags=("junction",),
    ),
    NcapScenario(
        "CBFA-50",
        "cyclist",
        "cyclist crossing from a farside side road",
        "crossing",
        "EBTa",
        20.0,
        speeds(10, 60),
        side="farside",
        lateral_offset_m=29.0,
        accel_distance_m=7.0,
        obstruction="CBFA",
        unverified=("parked-pair placement (vectorgrp #15)", "start ≈ 7 m behind the steady-state point"),
        sources="V23 CBFA",
        tags=("junction",),
    ),
    NcapScenario(
        "CBLA-50",
        "cyclist",
        "cyclist riding ahead in the lane, 50 %",
        "longitudinal",
        "EBTa",
        15.0,
        speeds(25, 60),
        side="ahead",
        accel_distance_m=3.5,
        steady_distance_m=28.0,
        sources="V23 CBLA-50",
    ),
    NcapScenario(
        "CBLA-25",
        "cyclist",
        "cyclist riding ahead in the lane, 25 %",
        "longitudinal",
        "EBTa",
        20.0,
        speeds(50, 80),
        impact_location=0.25,
        function="FCW",
        side="ahead",
        accel_distance_m=6.2,
        steady_distance_m=28.0,
        unverified=("FCW-only vs FCW-or-AEB wording",),
        sources="V23; FC26",
    ),
    NcapScenario(
        "CBTAfs",
        "cyclist",
        "farside turn across a cyclist riding the same direction",
        "turning",
        "EBTa",
        15.0,
        (Cell(10.0), Cell(15.0), Cell(20.0)),
        function="avoidance",
        turn="farside",
        side="farside",
        target_line_m=5.0,
        impact_side="left",
        unverified=("all CBTA parameters (FC26 only)", "side impact at 50 % of the VUT length"),
        sources="FC26",
        tags=("flying",),
    ),
    NcapScenario(
        "CBTAfo",
        "cyclist",
        "farside turn across an oncoming cyclist",
        "oncoming",
        "EBTa",
        15.0,
        (Cell(10.0), Cell(15.0), Cell(20.0)),
        function="avoidance",
        turn="farside",
        side="oncoming",
        target_line_m=2.75,
        unverified=("all CBTA parameters (FC26 only)",),
        sources="FC26",
    ),
    NcapScenario(
        "CBTAns",
        "cyclist",
        "nearside turn across a cyclist riding the same direction",
        "turning",
        "EBTa",
        15.0,
        (Cell(10.0),),
        function="avoidance",
        turn="nearside",
        target_line_m=5.0,
        impact_side="right",
        unverified=("all CBTA parameters (FC26 only)", "side impact at 50 % of the VUT length"),
        sources="FC26",
        tags=("flying",),
    ),
    NcapScenario(
        "CBTAno",
        "cyclist",
        "nearside turn across a cyclist riding the opposite direction",
        "turning",
        "EBTa",
        15.0,
        (Cell(10.0),),
        function="avoidance",
        turn="nearside",
        target_line_m=5.0,
        moves_with_vut=False,
        unverified=("all CBTA parameters (FC26 only)",),
        sources="FC26",
        tags=("flying",),
    ),
    # ---- motorcyclist ------------------------------------------------------------------------------------
    NcapScenario(
        "CMRs",
        "motorcyclist",
        "approaching a stationary motorcycle from behind",
        "rear",
        "EMT",
        0.0,
        speeds(10, 50, 10),
        side="ahead",
        unverified=("v4.5.1 speeds and offsets (FC26 values used)",),
        sources="FC26; RES",
    ),
    NcapScenario(
        "CMRs-FCW",
        "motorcyclist",
        "stationary motorcycle, FCW speeds",
        "rear",
        "EMT",
        0.0,
        speeds(60, 80, 10),
        function="FCW",
        side="ahead",
        unverified=("v4.5.1 speeds and offsets (FC26 values used)",),
        sources="FC26; RES",
    ),
    NcapScenario(
        "CMRb",
        "motorcyclist",
        "motorcycle ahead brakes at 4 m/s², 1.0 s headway",
        "rear",
        "EMT",
        0.0,
        speeds(30, 130, 10),
        side="ahead",
        headway_s=1.0,
        target_decel_mps2=4.0,
        unverified=("v4.5.1 speeds, headway and deceleration (FC26 values used)",),
        sources="FC26; RES",
    ),
    NcapScenario(
        "CMFtap",
        "motorcyclist",
        "farside turn across the path of an oncoming motorcycle",
        "oncoming",
        "EMT",
        30.0,
        tuple(Cell(v, f"EMT{m:.0f}", target_speed_kph=m) for v in (10.0, 15.0, 20.0) for m in (30.0, 45.0, 60.0)),
        function="avoidance",
        turn="farside",
        side="oncoming",
        target_line_m=1.75,
        sources="V23 CMFtap (C2C CCFtap base); FC26 §1.2.1.2",
    ),
    # ---- e-scooter: vrusim extension (Euro NCAP has no e-scooter target) ----------------------------------
    NcapScenario(
        "CENA-50",
        "escooter",
        "e-scooter crossing from the nearside (extension)",
        "crossing",
        "ESC",
        20.0,
        speeds(10, 60),
        lateral_offset_m=17.0,
        accel_distance_m=7.0,
        extension=True,
        sources="vrusim extension of CBNA (no obstruction); 20 km/h = EU e-scooter speed cap (e.g. DE eKFV)",
    ),
    NcapScenario(
        "CEFA-50",
        "escooter",
        "e-scooter crossing from the farside (extension)",
        "crossing",
        "ESC",
        20.0,
        speeds(10, 60),
        side="farside",
        lateral_offset_m=22.0,
        accel_distance_m=7.0,
        extension=True,
        sources="vrusim extension of CBFA (no obstruction)",
    ),
    NcapScenario(
        "CELA-50",
        "escooter",
        "e-scooter riding ahead in the lane at 13.4 m/s (extension)",
        "longitudinal",
        "ESC",
        13.4 / KPH,
        speeds(55, 80),
        side="ahead",
        accel_distance_m=22.4,
        steady_distance_m=28.0,
        extension=True,
        sources="vrusim extension of CBLA with the paper's e-scooter speed and footprint",
    ),
    NcapScenario(
        "CETAfs",
        "escooter",
        "farside turn across an e-scooter riding the same direction (extension)",
        "turning",
        "ESC",
        20.0,
        (Cell(10.0), Cell(15.0), Cell(20.0)),
        function="avoidance",
        turn="farside",
        side="farside",
        target_line_m=5.0,
        impact_side="left",
        extension=True,
        sources="vrusim extension of CBTAfs (side impact at 50 % of the VUT length)",
        tags=("flying",),
    ),
)
"""Every catalogue scenario; codes are unique. Night variants exist where `lighting` lists "night"."""

BY_CODE: dict[str, NcapScenario] = {s.code: s for s in SCENARIOS}


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
    "CBFA": Obstruction(("SUV", "small car"), False, 1.0, 22.0, 0.2, "V23 CBFA; placement UNVERIFIED (vectorgrp #15)"),
}
"""Parked obstruction rows by scenario family."""
