"""How a run ended: collision, avoided, stalled or incomplete (docs/metrics.md, "Outcome").

- `collision`: the bodies touched in an active step;
- `avoided`: no contact, and the ego completed its route (or was told to stand still: cruise speed 0);
- `stalled`: no contact, the route not completed, and the ego stood still (speed at most `STANDSTILL_MPS`) at
  the end of the run: it stopped short of its route end and did not move off again before the run ended;
- `incomplete`: no contact, the route not completed, and the ego still moving when `sim.duration_s` ran out.
"""

from __future__ import annotations

import numpy as np

__all__ = ["OUTCOMES", "STANDSTILL_MPS", "outcomes"]

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
