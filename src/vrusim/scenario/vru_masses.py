"""Default masses, kg: the ego and each VRU type with its vehicle (Δv, docs/metrics.md "Collision severity").

One table, read by the scenario model (`ego.mass_kg`, `vrus[k].mass_kg` when not given) and the docs.
"""

from __future__ import annotations

from typing import NamedTuple

from vrusim.scenario.vru_types import VruType


class MassDefault(NamedTuple):
    """A default mass, kg, and where it comes from."""

    mass_kg: float
    source: str


RIDER_KG = 75.0
"""Mass of a person, kg: the conventional "mass of the driver" of Regulation (EU) No 1230/2012 (75 kg);
Walpole et al. (2012, BMC Public Health 12:439) give 70.8 kg as the mean adult body mass in Europe."""

EGO_MASS = MassDefault(
    1500.0, "ours: a mid-size passenger car in running order (the EU new-car fleet averages about 1.5 t)"
)
"""Default `ego.mass_kg`."""

VRU_MASS: dict[VruType, MassDefault] = {
    VruType.PEDESTRIAN: MassDefault(RIDER_KG, "Reg. (EU) 1230/2012 person mass 75 kg"),
    VruType.CYCLIST: MassDefault(RIDER_KG + 15.0, "75 kg rider + 15 kg city bicycle (ours)"),
    VruType.E_SCOOTER: MassDefault(RIDER_KG + 15.0, "75 kg rider + 15 kg e-scooter (consumer models 12-20 kg; ours)"),
    VruType.MOTORCYCLIST: MassDefault(RIDER_KG + 200.0, "75 kg rider + 200 kg mid-size motorcycle, kerb mass (ours)"),
}
"""Default `vrus[k].mass_kg` per type: the person with the vehicle they ride."""
