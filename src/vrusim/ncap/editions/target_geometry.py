"""Where a scenario family's target starts, accelerates and runs: one table for both editions (lengths in m).

V23 = Vector's OpenSCENARIO encoding of v4.5.1 (our 2023 spec `reference/euroncap_vru.md`). FC26 draws these
distances in figures only (images, lost in the stored text), so the 2026 tables reuse the V23 values and flag
them UNVERIFIED; CMRb's headway and deceleration are FC26 §3.1.1.3 literals. The fields are those of
`NcapScenario` (docs/euroncap.md, "Geometry and synchronisation").
"""

from __future__ import annotations

TARGET_GEOMETRY: dict[str, dict[str, float]] = {
    # pedestrian (V23)
    "CPLA": {"accel_distance_m": 1.0, "steady_distance_m": 10.0},
    "CPTAfs": {"target_line_m": 9.5, "start_to_impact_m": 9.5, "accel_distance_m": 2.0},
    "CPTAno": {"target_line_m": 9.5, "start_to_impact_m": 9.5, "accel_distance_m": 2.0},
    "CPTAns": {"target_line_m": 9.5, "start_to_impact_m": 6.0, "accel_distance_m": 2.0},
    "CPTAfo": {"target_line_m": 9.5, "start_to_impact_m": 6.0, "accel_distance_m": 2.0},
    "CPNA": {"lateral_offset_m": 4.0, "accel_distance_m": 1.0},
    "CPFA": {"lateral_offset_m": 6.0, "accel_distance_m": 1.5},
    "CPNCO": {"lateral_offset_m": 4.0, "accel_distance_m": 1.0},
    # cyclist (V23)
    "CBLA": {"accel_distance_m": 3.5, "steady_distance_m": 28.0},
    "CBLA-FCW": {"accel_distance_m": 6.2, "steady_distance_m": 28.0},
    "CBNA": {"lateral_offset_m": 24.0, "accel_distance_m": 7.0},
    "CBNAO": {"lateral_offset_m": 11.5, "accel_distance_m": 7.0},
    "CBFA": {"lateral_offset_m": 29.0, "accel_distance_m": 7.0},
    "CBTA": {"target_line_m": 5.0},
    "CBTAfo": {"target_line_m": 2.75},
    # motorcyclist (CMRb: FC26 §3.1.1.3; CMFtap: V23 CMFtap, the C2C CCFtap base)
    "CMRb": {"headway_s": 1.0, "target_decel_mps2": 4.0},
    "CMFtap": {"target_line_m": 1.75},
}
"""Family -> `NcapScenario` geometry keyword arguments (`**TARGET_GEOMETRY[family]` in the edition tables)."""
