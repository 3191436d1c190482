"""LSC26 §3, the VRU scenarios of *Crash Avoidance – Low Speed Collisions* v1.1 (2026).

Every cell is in the standard range (the calculator has no extended range in LSC). A VUT starting from
standstill gets `vut_speed_kph` 0 ("SfS"). `ncap/build_low_speed.py` builds the layouts standstill_start,
pedal_misapplication and dooring; `ncap/build_turn_start.py` the standstill start inside a turn (CMFtap SfS).
"""

from __future__ import annotations

from vrusim.ncap.editions.target_geometry import TARGET_GEOMETRY
from vrusim.ncap.protocol import Cell, NcapScenario

CBNAO_SFS_OBSTRUCTION = {"vut_beside_m": 1.0, "obstruction_to_ebt_ref_m": 2.50}
"""LSC26 §3.2.1.1: 'initially positioned 1m beside the full obstruction'; 'The distance between the
obstruction and the EBT reference point is fixed to 2.50m'."""
CMCSCP_SFS_START_M = 2.9
"""LSC26 §3.1.2: 'longitudinal distance to the impact point of 2.9m' (VUT at standstill)."""
CPMRCM_TARGET_START_M = 10.0
"""LSC26 §3.2.2.1: 'The EPTc is initially positioned 10.00m away from the centre of the VUT trajectory'."""
CPMRCS_START_TTC_S = 2.0
"""LSC26 §3.2.2.2: the EPTc stands 'at a distance of 2s TTC from the VUT, measured from Tsteady'."""
CPMFC_TACC_TO_TARGET_M = (1.5, 0.5)
"""LSC26 §3.2.2.3: accelerator input at '1.5 + [0.5] m' from the EPTc (nominal, tolerance)."""
CPMFC_NO_CREEP_D_M = {"d1": 1.0, "d2": 1.5}
"""LSC26 §3.2.2.3: vehicles without creeping mode start at standstill 'd1=1.0m and d2 = 1.5m' away."""
CPMFC_CREEP_S = {"d2": 1.0}
"""LSC26 §3.2.2.3: 'd2: Distance travelled from standstill after creeping for [1]s' (d1: up to the maximum
creeping speed)."""
CBDA_DOOR_OPERATION_M = {10.0: (5.5, 0.4), 15.0: (8.0, 0.5), 20.0: (11.0, 0.7)}
"""LSC26 §3.2.3: door operation distance (nominal, + tolerance) by EBT speed km/h, bicyclist front reference
point to the most rearward point of the driver's door."""
SFS_TURN_PATH_KPH = 10.0
"""LSC26 §1.2.1: CCFtap SfS and CMFtap SfS follow 'the 10km/h to Farside case from the Frontal Collisions
protocol'."""
CENTRAL_MARKING_WIDTH_M = 0.10
"""LSC26 §3.1.4: the VUT stops with its front farside corner on the inner side of the (virtual) central lane
marking (± 0.10 m); §2.2 allows a dashed marking 0.10-0.15 m wide: the narrowest (UNVERIFIED)."""
CBDA_PATH_CLEARANCE_M = 1.0
"""LSC26 §3.2.3: VUT and obstruction car 'aligned one meter from the path of the VRU'."""


def _pairs(rows: tuple[float, ...], speeds: tuple[float, ...], label: str) -> tuple[Cell, ...]:
    """Cells gap/d × target speed at a standing VUT (speed 0), variant `<label><gap>-<speed>kph`."""
    return tuple(
        Cell(0.0, f"{label}{g:.2f}-T{t:g}", target_speed_kph=t, gap_m=g, row_label=f"{g:.2f} m")
        for g in rows
        for t in speeds
    )


LOW_SPEED: tuple[NcapScenario, ...] = (
    NcapScenario(
        "CBNAO-SfS",
        "cyclist",
        "VUT starts from standstill beside a full obstruction; cyclist from the nearside",
        "standstill_start",
        "EBTa",
        10.0,
        _pairs((1.5, 2.5), (10.0, 15.0, 20.0), "d"),
        function="avoidance",
        official="CBNAO SfS",
        sources="LSC26 §3.2.1.1 (d 1.50 / 2.50 m, EBT 10/15/20 km/h, steady at TTC 4 s)",
        unverified=(
            "impact location 50 % (LSC26: 50 ± 25 %)",
            "CA 102 start-off: 1.5 m/s² to 10 km/h (build_low_speed); cyclist at its test speed from t = 0",
        ),
    ),
    NcapScenario(
        "CPMRCm",
        "pedestrian",
        "reversing VUT (from standstill) toward a child walking in from the nearside",
        "standstill_start",
        "EPTc",
        5.0,
        _pairs((1.0, 1.5, 2.0), (5.0, 8.0), "gap"),
        function="avoidance",
        official="CPMRCm",
        sources="LSC26 §3.2.2.1 (rear gap 1.00/1.50/2.00 m, EPTc 5/8 km/h, start 10.00 m, 50 ± 25 %)",
        tags=("reverse",),
        unverified=("CA 102 start-off: 1.5 m/s² to 10 km/h; the child walks at its speed from t = 0",),
    ),
    NcapScenario(
        "CPMRCs",
        "pedestrian",
        "reversing VUT toward a standing child",
        "reverse",
        "EPTc",
        0.0,
        tuple(Cell(v, f"IL{p}", impact_location=p / 100) for v in (4.0, 8.0) for p in (25, 50, 75)),
        function="avoidance",
        official="CPMRCs",
        unverified=(
            "VUT reverses at its test speed from 10 m before the child (LSC26: accelerates from rest, "
            "steady from 2 s TTC)",
        ),
        sources="LSC26 §3.2.2.2 (4/8 km/h, 25/50/75 %)",
    ),
    NcapScenario(
        "CPMFC",
        "pedestrian",
        "creeping VUT, sudden full accelerator pedal toward a standing child",
        "pedal_misapplication",
        "EPTc",
        0.0,
        tuple(
            Cell(0.0, f"{d}-IL{p}", impact_location=p / 100, row_label=d) for d in ("d1", "d2") for p in (25, 50, 75)
        ),
        function="ACPE",
        official="CPMFC",
        sources="LSC26 §3.2.2.3 (d1/d2, 25/50/75 %, TACC 1.5 m before the child)",
        unverified=("creep 1.5 m/s, full accelerator 4 m/s² to 5 m/s; d2 = d1 + 1 s at the creep speed",),
    ),
    NcapScenario(
        "CBDA",
        "cyclist",
        "cyclist passing the parked VUT as the driver door is operated (dooring)",
        "dooring",
        "EBTa",
        10.0,
        _pairs((0.5, 1.0, 1.5, 2.0), (10.0, 15.0, 20.0), "gap"),
        function="dooring",
        official="CBDA",
        sources="LSC26 §3.2.3 (rear gap 0.50-2.00 m, EBT 10/15/20 km/h, door operation distances)",
        unverified=(
            "door 1.3 m behind the front, 1.1 m long, 60°/s to 60°; DOW sensor: 360° at the front",
            "assessed as door retention of the driver's door (R26 ceiling yellow); warning-only systems not modelled",
        ),
    ),
    NcapScenario(
        "CMCscp-SfS",
        "motorcyclist",
        "VUT starts from standstill 2.9 m before a junction; motorcycle from the farside hits 90 % of its left side",
        "standstill_start",
        "EMT",
        20.0,
        tuple(Cell(0.0, f"EMT{t:g}", target_speed_kph=t) for t in (20.0, 30.0, 40.0, 50.0, 60.0, 70.0, 80.0)),
        impact_location=0.9,
        function="avoidance",
        side="farside",
        impact_side="left",
        official="CMCscp SfS",
        sources="LSC26 §3.1.2 (EMT 20-80 km/h from the farside, 90 ± 10 % of the VUT length, start 2.9 m)",
        tags=("junction",),
        unverified=("the VUT's 90 % point travels 2.9 m to the impact; EMT at its test speed from t = 0",),
    ),
    NcapScenario(
        "CMFtap-SfS",
        "motorcyclist",
        "VUT starts from standstill in the 10 km/h farside turn; oncoming motorcycle",
        "standstill_start",
        "EMT",
        30.0,
        tuple(Cell(0.0, f"EMT{t:g}", target_speed_kph=t) for t in (30.0, 45.0, 60.0, 80.0)),
        function="avoidance",
        turn="farside",
        side="oncoming",
        **TARGET_GEOMETRY["CMFtap"],
        official="CMFtap SfS",
        unverified=("impact location 50 % (LSC26: 50 ± 25 %)",),
        sources="LSC26 §3.1.4 (EMT 30/45/60/80 km/h, 10 km/h farside path, stop at the central marking)",
    ),
)
"""LSC26 VRU scenarios (pedestrian & cyclist, and the motorcyclist parts of Car & PTW)."""
