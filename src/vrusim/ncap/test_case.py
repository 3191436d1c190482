"""The records of one Euro NCAP catalogue test (`NcapTest`, its `Nominal` impact, the `BuiltTest`) and the
vehicle under test with its onboard sensor, shared by the builders (`ncap/build.py`, `ncap/build_low_speed.py`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from vrusim.ncap.protocol import DUMMIES, KPH, Cell, Dummy, NcapScenario
from vrusim.scenario.schema import Scenario

VUT: dict[str, Any] = {
    "length_m": 4.5,
    "width_m": 1.8,
    "wheelbase_m": 2.7,
    "rear_overhang_m": 0.9,
    "max_decel_mps2": 9.0,
    "max_jerk_mps3": 30.0,
    "actuator_lag_s": 0.1,
}
"""Vehicle under test: a mid-size car; braking limits of a modern AEB (our choice, docs/euroncap.md)."""

SENSOR_RANGE_M, SENSOR_FOV_DEG = 20.0, 120.0
"""The onboard sensor of the VUT: the paper's default sector (day)."""


@dataclass(frozen=True)
class NcapTest:
    """One executable test of the catalogue: a scenario, one cell of its grid, and the lighting."""

    spec: NcapScenario
    cell: Cell
    lighting: str
    protocol: str
    """The edition the scenario comes from (ncap/editions)."""

    @property
    def test_id(self) -> str:
        """`CODE/<speed>kph[/variant]/<lighting>`, unique in the catalogue."""
        variant = f"/{self.cell.variant}" if self.cell.variant else ""
        return f"{self.spec.code}/{self.cell.vut_speed_kph:g}kph{variant}/{self.lighting}"

    @property
    def dummy(self) -> Dummy:
        """The target of this cell."""
        return DUMMIES[self.cell.target or self.spec.target]

    @property
    def impact_location(self) -> float:
        """Impact location, a fraction of the VUT's width (or of its length for side impacts)."""
        return self.cell.impact_location if self.cell.impact_location is not None else self.spec.impact_location

    @property
    def target_speed_mps(self) -> float:
        """The target's steady speed, m/s (the VUT's speed for a target driving ahead with a headway)."""
        if self.spec.headway_s > 0:
            return self.cell.vut_speed_kph * KPH
        kph = self.cell.target_speed_kph if self.cell.target_speed_kph is not None else self.spec.target_speed_kph
        return kph * KPH


@dataclass(frozen=True)
class Nominal:
    """Where and when the target meets the VUT if the VUT does not react (world frame, SI units)."""

    impact_x_m: float
    impact_y_m: float
    time_s: float
    local_x_m: float
    """Where the target's reference point is at first contact, in the simulated VUT frame: ahead of the
    rectangle centre, m (front impacts: the leading edge plus the circle's reach) ..."""
    local_y_m: float
    """... and left of it, m (front impacts: the impact location; a reversing VUT is simulated mirrored: its
    travel direction is ahead)."""
    ref_behind_centre_m: float
    """The reference point lies this far behind the footprint centre along the target's heading, m."""
    target_heading_rad: float
    steady_from_s: float
    """Time from which the target holds its steady speed, s (a standing target: 0)."""


@dataclass(frozen=True)
class BuiltTest:
    """A catalogue test as a validated Scenario plus its nominal impact."""

    test: NcapTest
    scenario: Scenario
    nominal: Nominal
