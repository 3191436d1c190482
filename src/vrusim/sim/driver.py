"""The driver model (`ego.driver`): packed phase tables, the per-step request, and its state.

Each step, from the ego state at t, the phase latch advances (a phase starts once its time or route distance is
reached and every earlier phase has started) and the driver's request is

    a_driver = clip((v_target - v) / dt, -rate, +rate)

(before the first phase: v_target = 0 at the ego's `max_decel_mps2`, the brake holding the ego). So a phase
reaches its target speed exactly, at constant acceleration `rate` until the last step. `idle` is the request with
the accelerator released: toward the creep speed at the creep rate (LSC26 Definitions, "Creeping").
Variants without a driver request 0 and their planner decides alone; nothing runs when no variant has a driver.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from vrusim.kernels import batch_kernel, prange
from vrusim.scenario.schema import Ego

START_TIME, START_ROUTE = 0, 1
"""Codes of `DriverArrays.start_kind`: a phase starts at a time (s) or at a route distance (m)."""


class DriverArrays(NamedTuple):
    """Driver schedules of a batch: [B] per variant, [B, P] per phase (P = most phases; padding unused)."""

    has: np.ndarray
    """The variant has a driver (bool)."""
    count: np.ndarray
    """Number of phases (int64)."""
    start_kind: np.ndarray
    start_value: np.ndarray
    target_speed_mps: np.ndarray
    rate_mps2: np.ndarray
    accelerator: np.ndarray
    creep_speed_mps: np.ndarray
    creep_accel_mps2: np.ndarray


def pack_driver(egos: list[Ego]) -> DriverArrays:
    """Pack each ego's `driver` (None: no driver) into `DriverArrays`."""
    B = len(egos)
    P = max((len(e.driver.phases) for e in egos if e.driver is not None), default=0)
    kind, value = np.zeros((B, P), dtype=np.int8), np.zeros((B, P))
    target, rate, pedal = np.zeros((B, P)), np.ones((B, P)), np.zeros((B, P), dtype=bool)
    creep_v, creep_a = np.zeros(B), np.ones(B)
    count = np.zeros(B, dtype=np.int64)
    for b, ego in enumerate(egos):
        driver = ego.driver
        if driver is None:
            continue
        count[b] = len(driver.phases)
        creep_v[b], creep_a[b] = driver.creep_speed_mps, driver.creep_accel_mps2
        for j, phase in enumerate(driver.phases):
            if phase.at_time_s is not None:
                kind[b, j], value[b, j] = START_TIME, phase.at_time_s
            else:
                kind[b, j], value[b, j] = START_ROUTE, phase.ego_route_m
            target[b, j], rate[b, j], pedal[b, j] = phase.target_speed_mps, phase.accel_mps2, phase.accelerator
    return DriverArrays(count > 0, count, kind, value, target, rate, pedal, creep_v, creep_a)


@dataclass
class DriverState:
    """Per variant [B]: the running phase (-1: none yet) and this step's request."""

    phase: np.ndarray
    accel_mps2: np.ndarray
    """The driver's requested acceleration, m/s^2 (0 without a driver)."""
    idle_accel_mps2: np.ndarray
    """The request with the accelerator released (creeping), m/s^2 (0 without a driver)."""
    accelerator: np.ndarray
    """The accelerator pedal is pressed (bool)."""


def initial_driver(size: int) -> DriverState:
    """No phase started, no request."""
    return DriverState(np.full(size, -1, dtype=np.int64), np.zeros(size), np.zeros(size), np.zeros(size, dtype=bool))


def update_driver(driver: DriverArrays, state: DriverState, t_s: float, dt_s: float, speed_mps, station_m, max_decel):
    """Advance the phase latch on the ego state at `t_s` and write this step's request into `state`."""
    _driver_step(
        state.phase.shape[0], t_s, dt_s, driver.has, driver.count, driver.start_kind, driver.start_value,
        driver.target_speed_mps, driver.rate_mps2, driver.accelerator, driver.creep_speed_mps,
        driver.creep_accel_mps2, max_decel, speed_mps, station_m, state.phase, state.accel_mps2,
        state.idle_accel_mps2, state.accelerator,
    )  # fmt: skip


@batch_kernel
def _driver_step(
    t,
    dt,
    has,
    count,
    kind,
    value,
    target,
    rate,
    pedal,
    creep_v,
    creep_a,
    max_decel,
    speed,
    station,
    phase,
    request,
    idle,
    accelerator,
):  # pragma: no cover (compiled)
    for b in prange(has.shape[0]):
        if not has[b]:
            continue
        while phase[b] + 1 < count[b]:
            j = phase[b] + 1
            now = t if kind[b, j] == START_TIME else station[b]
            if now < value[b, j] - 1e-9:
                break
            phase[b] = j
        v = speed[b]
        j = phase[b]
        if j < 0:
            goal, r, pressed = 0.0, max_decel[b], False
        else:
            goal, r, pressed = target[b, j], rate[b, j], pedal[b, j]
        request[b] = min(max((goal - v) / dt, -r), r)
        idle[b] = min(max((creep_v[b] - v) / dt, -creep_a[b]), creep_a[b])
        accelerator[b] = pressed
