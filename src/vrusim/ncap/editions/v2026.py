"""Euro NCAP Crash Avoidance 2026 (FC26 / LSC26 v1.1): the scenario table of the `2026` edition.

FC26 = *Crash Avoidance – Frontal Collisions* v1.1, LSC26 = *Low Speed Collisions* v1.1 (Oct 2025); the
digest is reference/euroncap_2026.md. Pedestrian and cyclist scenarios: editions/fc26_vru.py; motorcyclist:
editions/fc26_ptw.py; low speed: editions/lsc26.py; robustness layers: editions/robustness26.py. Grids
are the official calculator's (euroncap_rating_2026), cell by cell, including standard / extended tags.
"""

from __future__ import annotations

from vrusim.ncap.editions import Edition
from vrusim.ncap.editions.fc26_ptw import MOTORCYCLIST
from vrusim.ncap.editions.fc26_vru import CYCLIST, PEDESTRIAN
from vrusim.ncap.editions.lsc26 import LOW_SPEED
from vrusim.ncap.protocol import NcapScenario

SCENARIOS: tuple[NcapScenario, ...] = PEDESTRIAN + CYCLIST + MOTORCYCLIST + LOW_SPEED
"""Every 2026 VRU scenario (no vrusim extensions); codes are unique."""

EDITION = Edition(
    "2026",
    "Euro NCAP Crash Avoidance 2026: Frontal Collisions v1.1 and Low Speed Collisions v1.1 (VRU scenarios)",
    "FC26, LSC26 (reference/euroncap_2026.md); ranges from euroncap-rating-2026",
    SCENARIOS,
)
