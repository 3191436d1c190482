"""How a run ended: collision, avoided, stalled or incomplete (docs/metrics.md, "Outcome").

- `collision`: the bodies touched in an active step;
- `avoided`: no contact, and the ego completed its route (or was told to stand still: cruise speed 0);
- `stalled`: no contact, the route not completed, and the ego stood still (speed at most `STANDSTILL_MPS`) at
  the end of the run: it stopped short of its route end and did not move off again before the run ended;
- `incomplete`: no contact, the route not completed, and the ego still moving when `sim.duration_s` ran out.
"""

from __future__ import annotations

import numpy as np

__all__ = ["OUTCOMES", "STANDSTILL_MPS", "outcome_counts", "outcome_of", "outcomes"]

OUTCOMES = ("collision", "avoided", "stalled", "incomplete")
"""Every outcome, in the order above."""
STANDSTILL_MPS = 0.01
"""Ego speed at or below which the ego stands still, m/s (the engine clips a stopped ego to exactly 0)."""


def outcomes(
    collided: np.ndarray, route_completed: np.ndarray, cruise_speed_mps: np.ndarray, final_speed_mps: np.ndarray
) -> np.ndarray:
    """The outcome of each variant (an object array of the names in `OUTCOMES`)."""
    finished = np.asarray(route_completed, dtype=bool) | (np.asarray(cruise_speed_mps) <= 0.0)
    standing = np.abs(np.asarray(final_speed_mps)) <= STANDSTILL_MPS
    out = np.where(finished, "avoided", np.where(standing, "stalled", "incomplete"))
    return np.where(np.asarray(collided, dtype=bool), "collision", out).astype(object)


def outcome_of(row: dict) -> str:
    """The outcome of a summary row; rows written before outcomes existed (no `outcome` key) read collision or
    avoided from `collided`."""
    return row.get("outcome") or ("collision" if row["collided"] else "avoided")


def outcome_counts(rows: list[dict]) -> str:
    """ "2 collisions, 1 avoided, 1 stalled": the count of each outcome that occurs, in `OUTCOMES` order."""
    found = [outcome_of(row) for row in rows]
    parts = []
    for name in OUTCOMES:
        count = found.count(name)
        if count:
            parts.append(f"{count} {name}{'s' if name == 'collision' and count != 1 else ''}")
    return ", ".join(parts)
