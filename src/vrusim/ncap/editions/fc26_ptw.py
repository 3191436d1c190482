"""FC26 §3.1, car-to-motorcyclist scenarios of *Crash Avoidance – Frontal Collisions* v1.1 (2026).

Grids are FC26 §3.1 tables; standard / extended tags come from the official calculator (grid26.py).
"""

from __future__ import annotations

from vrusim.ncap.editions.grid26 import il_grid, speed_grid
from vrusim.ncap.editions.target_geometry import TARGET_GEOMETRY
from vrusim.ncap.protocol import NcapScenario

PTW_IL = (90, 75, 50, 25, 10)
"""FC26 §3.1.1.3 CMRs / CMRb impact locations, %."""
CMCSCP_SPEEDS = (20.0, 30.0, 40.0, 50.0, 60.0, 70.0, 80.0)
"""FC26 §3.1.3.2: VUT and EMT speeds of CMCscp, km/h."""
CMCSCP_NA = tuple((v, t) for v in (40.0, 50.0, 60.0) for t in (70.0, 80.0)) + tuple(
    (v, t) for v in (70.0, 80.0) for t in (40.0, 50.0, 60.0, 70.0, 80.0)
)
"""FC26 §3.1.3.2: the N/A cells (VUT, EMT) of the CMCscp grid."""
CMCSCP_EXTENDED = ((20.0, 70.0), (20.0, 80.0), (30.0, 70.0), (30.0, 80.0),
                   (70.0, 20.0), (70.0, 30.0), (80.0, 20.0), (80.0, 30.0))  # fmt: skip
"""The calculator's CMCscp EXTENDED_RANGE_CELLS as (VUT, EMT) km/h."""
CMCSCP_START = "EMT moves at its test speed from the start (FC26: accelerates > 1 m/s², 0.5 s stabilisation)"

MOTORCYCLIST: tuple[NcapScenario, ...] = (
    NcapScenario(
        "CMRs",
        "motorcyclist",
        "approaching a stationary motorcycle from behind (AEB 10-50, FCW 60-80)",
        "rear",
        "EMT",
        0.0,
        il_grid((10.0, 20.0, 30.0, 40.0, 50.0), PTW_IL, (75, 50, 25))
        + il_grid((60.0, 70.0, 80.0), PTW_IL, (75, 50, 25), function="FCW"),
        side="ahead",
        official="CMRs",
        sources="FC26 §3.1.1.3 (grid, FCW rows 60-80); calculator (ranges)",
    ),
    NcapScenario(
        "CMRb",
        "motorcyclist",
        "motorcycle ahead at the VUT's speed brakes at 4 m/s², 1.0 s headway",
        "rear",
        "EMT",
        0.0,
        il_grid(
            tuple(float(v) for v in range(30, 140, 10)),
            PTW_IL,
            (75, 50, 25),
            extended_speeds_kph=(90.0, 100.0, 110.0, 120.0, 130.0),
        ),
        side="ahead",
        **TARGET_GEOMETRY["CMRb"],
        official="CMRb",
        sources="FC26 §3.1.1.3 (grid, 'Time Headway = 1.0 s', 'target acceleration = -4 m/s2'); calculator",
    ),
    NcapScenario(
        "CMFtap",
        "motorcyclist",
        "farside turn across the path of an oncoming motorcycle",
        "oncoming",
        "EMT",
        30.0,
        speed_grid(
            (10.0, 15.0, 20.0, 25.0),
            (30.0, 45.0, 60.0, 80.0),
            [(v, 80.0) for v in (10.0, 15.0, 20.0, 25.0)] + [(25.0, t) for t in (30.0, 45.0, 60.0)],
        ),
        function="avoidance",
        turn="farside",
        side="oncoming",
        **TARGET_GEOMETRY["CMFtap"],
        official="CMFtap",
        sources="FC26 §3.1.2.2 (grid, paths 1.75 m from the centre marking, front wheel at 50 %); §1.2.4 "
        "(20 and 25 km/h path); calculator (ranges)",
    ),
    NcapScenario(
        "CMCscp",
        "motorcyclist",
        "motorcycle crossing from the nearside behind three parked cars; hits 90 % of the VUT's right side",
        "crossing",
        "EMT",
        20.0,
        tuple(
            c
            for c in speed_grid(CMCSCP_SPEEDS, CMCSCP_SPEEDS, CMCSCP_EXTENDED, skip=CMCSCP_NA)
            if c.range == "standard"
        ),
        impact_location=0.9,
        function="avoidance",
        impact_side="right",
        obstruction="CMCscp",
        official="CMCscp",
        unverified=(CMCSCP_START, "nearside approach (FC26: nearside or farside, drawn at random)"),
        sources="FC26 §3.1.3.2 (grid, N/A cells, 90 % side impact, obstruction in the standard range)",
        tags=("junction", "flying"),
    ),
    NcapScenario(
        "CMCscp-ext",
        "motorcyclist",
        "motorcycle crossing from the nearside, unobstructed (extended range)",
        "crossing",
        "EMT",
        20.0,
        tuple(
            c
            for c in speed_grid(CMCSCP_SPEEDS, CMCSCP_SPEEDS, CMCSCP_EXTENDED, skip=CMCSCP_NA)
            if c.range == "extended"
        ),
        impact_location=0.9,
        function="avoidance",
        impact_side="right",
        official="CMCscp",
        unverified=(CMCSCP_START, "nearside approach (FC26: nearside or farside, drawn at random)"),
        sources="FC26 §3.1.3.2 ('without obstruction for Extended Range'); calculator (ranges)",
        tags=("junction", "flying"),
    ),
)
"""FC26 car-to-motorcyclist scenarios (the car-to-car ones are outside vrusim's scope)."""
