"""Default properties per VRU type: the single table every other module reads.

Speeds and footprint radii for pedestrian, e-scooter and motorcyclist come from the paper
(He et al., CPSI 2025, Sec. IV-A). Cyclist values and all accelerations are ours; sources in docs/models.md.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum


class VruType(StrEnum):
    """Kinds of vulnerable road user."""

    PEDESTRIAN = "pedestrian"
    CYCLIST = "cyclist"
    E_SCOOTER = "e_scooter"
    MOTORCYCLIST = "motorcyclist"


@dataclass(frozen=True)
class VruDefaults:
    """Type defaults: top speed (m/s), acceleration limit (m/s^2), footprint radius (m)."""

    top_speed_mps: float
    max_accel_mps2: float
    radius_m: float
    source: str


VRU_DEFAULTS: dict[VruType, VruDefaults] = {
    VruType.PEDESTRIAN: VruDefaults(
        1.8, 1.0, 0.5, "paper Sec. IV-A (speed, radius); accel: Euro NCAP EPT 5 km/h within 1 m ≈ 1 m/s²"
    ),
    VruType.CYCLIST: VruDefaults(
        5.56,
        2.5,
        0.95,
        "Euro NCAP EBTa 20 km/h, 1.89 m target length (radius = half length); 15 km/h in 3.5 m",
    ),
    VruType.E_SCOOTER: VruDefaults(13.4, 4.0, 1.0, "paper Sec. IV-A (speed, radius); accel: ours, docs/models.md"),
    VruType.MOTORCYCLIST: VruDefaults(30.0, 5.0, 1.5, "paper Sec. IV-A (speed, radius); accel: ours, docs/models.md"),
}
