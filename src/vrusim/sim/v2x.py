"""V2X: a roadside unit (RSU) that perceives VRUs in its coverage and a channel that delivers its messages.

The RSU knows the state of every VRU within `coverage_range_m` of it. The ego receives the RSU's VRU
awareness messages while the centre of its rectangle is within `comm_range_m` of the RSU. What reaches the
planner passes through a channel object; `IdealChannel` delivers every message at once and intact (the
paper's assumption). A realistic channel implements the same `deliver` method.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np

from vrusim.sim.batch import BatchParams


@dataclass
class V2xMessages:
    """VRU states as received by each ego, [B, K]; `received` marks valid entries, `age_s` their age."""

    received: np.ndarray
    x_m: np.ndarray
    y_m: np.ndarray
    vx_mps: np.ndarray
    vy_mps: np.ndarray
    age_s: np.ndarray


class Channel(Protocol):
    """Delivers what the RSU sends to the ego; may delay, drop or cut messages."""

    def reset(self, params: BatchParams) -> None: ...

    def deliver(self, t_s: float, sent: V2xMessages) -> V2xMessages: ...


class IdealChannel:
    """Zero latency, no loss, no outage."""

    def reset(self, params: BatchParams) -> None:
        """Nothing to set up."""

    def deliver(self, t_s: float, sent: V2xMessages) -> V2xMessages:
        """Everything sent arrives now."""
        return sent


def rsu_broadcast(params: BatchParams, ego_x, ego_y, vru_x, vru_y, vru_vx, vru_vy) -> V2xMessages:
    """What the RSU sends to each ego this step: VRUs in its coverage, if the ego is within range."""
    ex, ey = ego_x - params.rsu_x_m, ego_y - params.rsu_y_m
    ego_in_range = params.v2x_enabled & (ex * ex + ey * ey <= params.comm_range_m**2)
    vx, vy = vru_x - params.rsu_x_m[:, None], vru_y - params.rsu_y_m[:, None]
    covered = vx * vx + vy * vy <= (params.coverage_range_m**2)[:, None]
    received = covered & ego_in_range[:, None] & params.vru_valid
    return V2xMessages(received, vru_x, vru_y, vru_vx, vru_vy, np.zeros(received.shape))
