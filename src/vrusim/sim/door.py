"""The door model (`ego.door`, Euro NCAP CBDA): packed geometry, the per-step opening and the door-VRU contact.

Frames: the door is given on the real body (ISO 8855: x forward, y left, origin at the ego rectangle's centre) and
packed into the simulated vehicle frame, which for a reversing ego is the body mirrored front to back
(docs/models.md, "Reversing"): every point and vector times m = -1. With opening angle theta and side sign s
(+1 left, -1 right) the door, hinged at H = m (L/2 - hinge_from_front, s W/2), points along
d = m (-cos theta, s sin theta) and its outward normal is n = m (sin theta, s cos theta); it is the rectangle
from H along d for its length, from the hinge line outward along n for its thickness. Its outer rear corner is
H + length d + thickness n. Contact with a VRU's circle is the exact rectangle-circle clearance
(`geometry.contact.clearance_local`), checked only while the door is open (theta > 0); the closed door is part
of the body. Nothing here runs when no variant has a door.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from vrusim.geometry.contact import clearance_local, to_local
from vrusim.kernels import batch_kernel, njit, prange
from vrusim.scenario.schema import Ego

DOOR_AT_TIME, DOOR_VRU_DISTANCE = 0, 1
"""Codes of `DoorArrays.trigger_kind`."""


class DoorArrays(NamedTuple):
    """Doors of a batch, [B] each, in the simulated vehicle frame (see the module docstring)."""

    has: np.ndarray
    hinge_x_m: np.ndarray
    hinge_y_m: np.ndarray
    side_sign: np.ndarray
    """s: +1 a left door, -1 a right door (of the real body)."""
    mirror: np.ndarray
    """m: -1 for a reversing ego (mirrored frame), else +1."""
    length_m: np.ndarray
    thickness_m: np.ndarray
    max_angle_rad: np.ndarray
    rate_rad_ps: np.ndarray
    delay_s: np.ndarray
    trigger_kind: np.ndarray
    trigger_value: np.ndarray
    trigger_vru: np.ndarray
    rear_x_m: np.ndarray
    """x of the closed door's rear edge, m."""


def pack_door(egos: list[Ego]) -> DoorArrays:
    """Pack each ego's `door` (None: no door) into `DoorArrays`."""
    B = len(egos)
    rows = np.zeros((11, B))  # the float fields of DoorArrays from hinge_x_m to rear_x_m, in order
    rows[2:4] = 1.0  # side, mirror
    kind = np.zeros(B, dtype=np.int8)
    vru = np.zeros(B, dtype=np.int64)
    has = np.zeros(B, dtype=bool)
    for b, ego in enumerate(egos):
        door = ego.door
        if door is None:
            continue
        has[b] = True
        m = -1.0 if ego.reverse else 1.0
        s = 1.0 if door.side == "left" else -1.0
        hinge_x = ego.length_m / 2 - door.hinge_from_front_m
        trig = door.trigger
        kind[b] = DOOR_AT_TIME if trig.at_time_s is not None else DOOR_VRU_DISTANCE
        vru[b] = trig.vru
        rows[:, b] = (
            m * hinge_x, m * s * ego.width_m / 2, s, m, door.length_m, door.thickness_m,
            math.radians(door.max_angle_deg), math.radians(door.opening_rate_deg_ps), door.delay_s,
            trig.at_time_s if trig.at_time_s is not None else trig.vru_distance_m, m * (hinge_x - door.length_m),
        )  # fmt: skip
    return DoorArrays(has, *rows[:9], kind, rows[9], vru, rows[10])


@dataclass
class DoorState:
    """Per variant [B]: the door operation (requested, time the door starts moving) and the opening angle."""

    requested: np.ndarray
    open_at_s: np.ndarray
    angle_rad: np.ndarray
    hit: np.ndarray
    """[B, K]: this step's clearance to VRU k is the door's (it is nearer than the body)."""


def initial_door(size: int, slots: int) -> DoorState:
    """Every door closed, not operated."""
    return DoorState(
        np.zeros(size, dtype=bool), np.full(size, np.inf), np.zeros(size), np.zeros((size, slots), dtype=bool)
    )


@njit(cache=True, inline="always")
def door_rectangle(door_hinge_x, door_hinge_y, s, m, length, thickness, angle):  # pragma: no cover (compiled)
    """(centre x, centre y, heading x, heading y) of the door rectangle in the vehicle frame at `angle` (rad)."""
    c, sn = math.cos(angle), math.sin(angle)
    dx, dy = -m * c, m * s * sn
    nx, ny = m * sn, m * s * c
    return (
        door_hinge_x + 0.5 * length * dx + 0.5 * thickness * nx,
        door_hinge_y + 0.5 * length * dy + 0.5 * thickness * ny,
        dx,
        dy,
    )


def door_outer_corner(door: DoorArrays, angle_rad: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The outer rear corner H + length d + thickness n of each door at `angle_rad` [B], vehicle frame, m."""
    c, sn = np.cos(angle_rad), np.sin(angle_rad)
    m, s = door.mirror, door.side_sign
    x = door.hinge_x_m + door.length_m * (-m * c) + door.thickness_m * (m * sn)
    y = door.hinge_y_m + door.length_m * (m * s * sn) + door.thickness_m * (m * s * c)
    return x, y


def update_doors(door: DoorArrays, state: DoorState, hold, t_s, t_next_s, ego, vru_x, vru_y, radius, contact):
    """Advance the doors over the step (t_s, t_next_s] (judged on the state at t_next_s) and fold the door-VRU
    clearance into `contact` [3, B, K] (clearance, outline x, outline y in the vehicle frame) where it is the
    nearer, marking those pairs in `state.hit`."""
    _door_step(
        state.angle_rad.shape[0], t_s, t_next_s, door.has, door.hinge_x_m, door.hinge_y_m, door.side_sign,
        door.mirror, door.length_m, door.thickness_m, door.max_angle_rad, door.rate_rad_ps, door.delay_s,
        door.trigger_kind, door.trigger_value, door.trigger_vru, door.rear_x_m, hold, ego.centre_x_m,
        ego.centre_y_m, ego.heading_x, ego.heading_y, vru_x, vru_y, radius, state.requested, state.open_at_s,
        state.angle_rad, state.hit, contact,
    )  # fmt: skip


@batch_kernel
def _door_step(
    t,
    t_next,
    has,
    hinge_x,
    hinge_y,
    side,
    mirror,
    length,
    thickness,
    max_angle,
    rate,
    delay,
    kind,
    value,
    vru,
    rear_x,
    hold,
    cx,
    cy,
    hx,
    hy,
    px,
    py,
    radius,
    requested,
    open_at,
    angle,
    hit,
    contact,
):  # pragma: no cover (compiled)
    B, K = px.shape
    for b in prange(B):
        if not has[b]:
            continue
        if not requested[b]:
            if kind[b] == DOOR_AT_TIME:
                fire = t_next >= value[b] - 1e-9
            else:
                k = vru[b]
                lx, _ = to_local(cx[b], cy[b], hx[b], hy[b], px[b, k], py[b, k])
                fire = abs(lx - rear_x[b]) - radius[b, k] <= value[b]
            if fire:
                requested[b] = True
                open_at[b] = t_next + delay[b]
        if requested[b] and not hold[b] and t_next > open_at[b]:
            angle[b] = min(max_angle[b], angle[b] + rate[b] * (t_next - max(t, open_at[b])))
        for k in range(K):
            hit[b, k] = False
        if angle[b] <= 0.0:
            continue
        dcx, dcy, dhx, dhy = door_rectangle(
            hinge_x[b], hinge_y[b], side[b], mirror[b], length[b], thickness[b], angle[b]
        )
        for k in range(K):
            lx, ly = to_local(cx[b], cy[b], hx[b], hy[b], px[b, k], py[b, k])  # vehicle frame
            ux, uy = to_local(dcx, dcy, dhx, dhy, lx, ly)  # door frame
            clearance, ox, oy = clearance_local(ux, uy, 0.5 * length[b], 0.5 * thickness[b], radius[b, k])
            if clearance < contact[0, b, k]:
                contact[0, b, k] = clearance
                contact[1, b, k] = dcx + ox * dhx - oy * dhy
                contact[2, b, k] = dcy + ox * dhy + oy * dhx
                hit[b, k] = True
