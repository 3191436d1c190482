"""V2X: a roadside unit (RSU) that perceives VRUs in its coverage and a channel that delivers its messages.

The RSU knows the state of every VRU within `coverage_range_m` of it. The ego receives the RSU's VRU
awareness messages while the centre of its rectangle is within `comm_range_m` of the RSU. What reaches the
planner passes through a channel object; `IdealChannel` delivers every message at once and intact (the
paper's assumption). `RealisticChannel` (`sim/v2x/channel.py`) adds message generation rules, delay, loss,
outages, RSU perception error and the ego's track memory, as each scenario's `v2x.channel` specifies.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np

from vrusim.kernels import batch_kernel, njit, prange
from vrusim.sim.params import BatchParams


@dataclass
class V2xMessages:
    """VRU states as received by each ego: `received` [B, K] marks valid entries, `kinematics` [6, B, K] holds
    position, velocity and acceleration (rows of `vrusim.sim.state.KINEMATICS`), `age_s` [B, K] their age.

    What the RSU sends also says which VRUs it perceives (`covered` [B, K], whether or not the ego is in
    range) and how far each ego is from it (`link_distance_m` [B]); channels that need neither ignore them.
    """

    received: np.ndarray
    kinematics: np.ndarray
    age_s: np.ndarray
    covered: np.ndarray | None = None
    link_distance_m: np.ndarray | None = None


class Channel(Protocol):
    """Delivers what the RSU sends to the ego; may delay, drop or cut messages."""

    def reset(self, params: BatchParams) -> None: ...

    def deliver(self, t_s: float, sent: V2xMessages) -> V2xMessages: ...


class IdealChannel:
    """Zero latency, no loss, no outage."""

    def reset(self, params: BatchParams) -> None:
        """Nothing to set up."""

    def compact(self, index: np.ndarray) -> None:
        """Nothing kept per variant."""

    def deliver(self, t_s: float, sent: V2xMessages) -> V2xMessages:
        """Everything sent arrives now."""
        return sent


def rsu_broadcast(params: BatchParams, ego_x, ego_y, vru_kinematics) -> V2xMessages:
    """What the RSU sends to each ego this step: VRUs in its coverage, if the ego is within range.

    The message arrays may be views of the simulation state: a channel that keeps messages must copy them.
    """
    received = np.empty(vru_kinematics.shape[1:], dtype=bool)
    covered = np.empty(received.shape, dtype=bool)
    link_distance = np.empty(params.size)
    _coverage(
        params.size,
        params.v2x_enabled,
        params.rsu_x_m,
        params.rsu_y_m,
        params.comm_range_m,
        params.coverage_range_m,
        params.vru_valid,
        ego_x,
        ego_y,
        vru_kinematics[0],
        vru_kinematics[1],
        received,
        covered,
        link_distance,
    )
    return V2xMessages(received, vru_kinematics, np.zeros(received.shape), covered, link_distance)


@batch_kernel
def _coverage(
    enabled, rsu_x, rsu_y, comm, coverage, valid, ego_x, ego_y, vru_x, vru_y, received, covered, link
):  # pragma: no cover (compiled)
    for b in prange(vru_x.shape[0]):
        coverage_variant(
            b, enabled, rsu_x, rsu_y, comm, coverage, valid, ego_x, ego_y, vru_x, vru_y, received, covered, link, True
        )


@njit(cache=True, inline="always")
def coverage_variant(
    b, enabled, rsu_x, rsu_y, comm, coverage, valid, ego_x, ego_y, vru_x, vru_y, received, covered, link, with_link
):  # pragma: no cover (compiled)
    """What the RSU sends to variant b's ego (`rsu_broadcast`); the link distance (m) only `with_link` (the
    realistic channel reads it, the ideal one does not)."""
    ex, ey = ego_x[b] - rsu_x[b], ego_y[b] - rsu_y[b]
    if with_link:
        link[b] = np.sqrt(ex * ex + ey * ey)
    in_range = enabled[b] and ex * ex + ey * ey <= comm[b] * comm[b]
    for k in range(vru_x.shape[1]):
        vx, vy = vru_x[b, k] - rsu_x[b], vru_y[b, k] - rsu_y[b]
        covered[b, k] = enabled[b] and valid[b, k] and vx * vx + vy * vy <= coverage[b] * coverage[b]
        received[b, k] = in_range and covered[b, k]
