"""Per-variant values of the collision-severity and surrogate safety metrics, from the engine's accumulators.

Each function takes a batch view (`vrusim.metrics.catalog.BatchView`) and returns one value per variant (NaN:
absent); the catalogue declares them. Formulas, units and sources: docs/metrics.md ("Collision severity",
"Surrogate safety measures", "Per-VRU minima").
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from vrusim.metrics.injury_risk import SERIOUS_INJURY_CURVE, risk

BatchView = Any
"""`vrusim.metrics.catalog.BatchView` (not imported: the catalogue imports this module)."""

__all__ = [
    "delta_v_ego",
    "delta_v_vru",
    "fatality_risk",
    "peak_btn",
    "per_vru_columns",
    "per_vru_json",
    "pet",
    "plastic_delta_v",
    "serious_injury_risk",
    "speed_reduction",
]


def _hit(view: BatchView) -> tuple[np.ndarray, np.ndarray]:
    """(collided [B], slot of the VRU hit [B], 0 where none)."""
    collided = np.asarray(view.accumulators.collided, dtype=bool)
    slot = np.where(collided, view.accumulators.impact_vru, 0).astype(np.int64)
    return collided, np.clip(slot, 0, max(view.params.vru_slots - 1, 0))


def speed_reduction(view: BatchView) -> np.ndarray:
    """Cruise (planned) speed minus the ego's impact speed, m/s; NaN without a collision."""
    collided, _ = _hit(view)
    reduction = view.params.cruise_speed_mps - view.accumulators.impact_ego_speed_mps
    return np.where(collided, reduction, np.nan)


def plastic_delta_v(
    ego_mass_kg: np.ndarray, vru_mass_kg: np.ndarray, relative_speed_mps: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """(ego Δv, VRU Δv), m/s, of a perfectly plastic collision at that relative speed (momentum conserved)."""
    total = np.asarray(ego_mass_kg, dtype=float) + vru_mass_kg
    speed = np.abs(relative_speed_mps)
    return vru_mass_kg / total * speed, ego_mass_kg / total * speed


def _delta_v(view: BatchView, of_ego: bool) -> np.ndarray:
    collided, slot = _hit(view)
    p = view.params
    vru_mass = p.vru_mass_kg[np.arange(view.size), slot]
    speed = np.where(collided, view.accumulators.impact_relative_speed_mps, 0.0)
    ego, vru = plastic_delta_v(p.ego_mass_kg, vru_mass, speed)
    return ego if of_ego else vru


def delta_v_ego(view: BatchView) -> np.ndarray:
    """Ego Δv of a plastic collision, m/s: m_vru / (m_ego + m_vru) |v_rel|; 0 without a collision."""
    return _delta_v(view, of_ego=True)


def delta_v_vru(view: BatchView) -> np.ndarray:
    """VRU Δv of a plastic collision, m/s: m_ego / (m_ego + m_vru) |v_rel|; 0 without a collision."""
    return _delta_v(view, of_ego=False)


def _impact_speed(view: BatchView) -> np.ndarray:
    collided, _ = _hit(view)
    return np.where(collided, view.accumulators.impact_relative_speed_mps, 0.0)


def fatality_risk(view: BatchView) -> np.ndarray:
    """Fatality risk at the impact speed on each variant's `metrics.injury_risk_curve`; 0 without a collision."""
    collided, _ = _hit(view)
    speed = _impact_speed(view)
    out = np.zeros(view.size)
    curves = np.array(view.params.injury_risk_curves, dtype=object)
    for curve in set(view.params.injury_risk_curves):
        rows = curves == curve
        out[rows] = risk(speed[rows], curve)
    return np.where(collided, out, 0.0)


def serious_injury_risk(view: BatchView) -> np.ndarray:
    """Serious-injury (AIS 4+) risk at the impact speed; 0 without a collision."""
    collided, _ = _hit(view)
    return np.where(collided, risk(_impact_speed(view), SERIOUS_INJURY_CURVE), 0.0)


def peak_btn(view: BatchView) -> np.ndarray:
    """Brake threat number at the DRAC peak: peak DRAC / `ego.max_decel_mps2`."""
    return view.accumulators.peak_drac_mps2 / view.params.max_decel_mps2


def _valid(view: BatchView, row: np.ndarray) -> np.ndarray:
    values = np.where(view.params.vru_valid, row, np.nan)
    return np.where(np.isfinite(values), values, np.nan)


def pet(view: BatchView) -> np.ndarray:
    """Smallest post-encroachment time over the VRUs, s; NaN when no VRU's is known."""
    values = _valid(view, view.accumulators.vru_row("pet_s"))
    out = np.full(view.size, np.nan)
    known = ~np.all(np.isnan(values), axis=1) if values.shape[1] else np.zeros(view.size, dtype=bool)
    out[known] = np.nanmin(values[known], axis=1)
    return out


def per_vru(row: str) -> Any:
    """The compute of a per-VRU metric: the accumulator row [B, K], NaN in empty slots and where infinite."""

    def compute(view: BatchView) -> np.ndarray:
        return _valid(view, view.accumulators.vru_row(row))

    return compute


def per_vru_columns(template: str) -> Any:
    """The split of a per-VRU metric into one column per slot, named `template.format(k=slot)`."""

    def split(view: BatchView, values: np.ndarray) -> dict[str, np.ndarray]:
        return {template.format(k=k): values[:, k] for k in range(values.shape[1])}

    return split


def per_vru_json(template: str, digits: int = 6) -> Any:
    """The JSON value of a per-VRU metric: a list over the variant's VRUs (None where absent)."""

    def to_json(view: BatchView, columns: dict[str, np.ndarray]) -> list[list[float | None]]:
        counts = view.params.vru_valid.sum(axis=1).tolist()
        slots = [columns[template.format(k=k)].tolist() for k in range(view.params.vru_slots)]
        return [
            [round(float(slots[k][b]), digits) if math.isfinite(slots[k][b]) else None for k in range(count)]
            for b, count in enumerate(counts)
        ]

    return to_json
