"""VRU motion: point masses driven along their prescribed paths by a force toward the top speed.

Along the path, acceleration a = clip((v_target - v) / max(tau, dt), -a_max, a_max): with tau = 0 the VRU
accelerates at a_max from rest and holds its top speed exactly (Euro NCAP targets); tau > 0 gives the
exponential approach of the social-force driving term (Helbing & Molnár 1995). A VRU holds its initial speed
(usually 0: standing) until its trigger fires (at a time; when the ego's front bumper is within a distance, or a
time-to-arrival at its current speed, of a point; when the ego has travelled a distance along its route; or
when the ego's speed is at or below / at or above a value, or it has stood still for a time, checked at step
starts);
from then on it follows its profile open-loop and never reacts to the ego. An optional braking phase starts a
set time after the trigger: the target speed becomes 0 and the deceleration is limited to its own value.
A trigger is checked at step starts, but the profile starts at the instant inside the last step when the
condition was met (time and route triggers; interpolated at the ego's speed), so synchronisation does not
carry a one-step error.
"""

from __future__ import annotations

import numpy as np

from vrusim.geometry.path_table import locate_point
from vrusim.kernels import batch_kernel, njit, prange
from vrusim.sim.params import BatchParams
from vrusim.sim.state import VruState
from vrusim.sim.vru.registry import POINT_MASS, attach_vru_step
from vrusim.sim.vru.triggers import fire_trigger


def advance_vrus(
    params: BatchParams,
    vrus: VruState,
    t_s: float,
    front_x: np.ndarray,
    front_y: np.ndarray,
    ego_speed: np.ndarray,
    ego_station: np.ndarray,
) -> None:
    """Fire triggers from the ego state at t_s, then advance every VRU by one step (in place)."""
    _advance(
        params.size,
        params.vru_paths.arrays,
        params.vru_path_offset,
        params.trigger_kind,
        params.trigger_value,
        params.trigger_x_m,
        params.trigger_y_m,
        params.vru_top_speed_mps,
        params.vru_max_accel_mps2,
        params.vru_tau_s,
        params.vru_initial_speed_mps,
        params.vru_brake_after_s,
        params.vru_brake_decel_mps2,
        params.dt_s,
        t_s,
        front_x,
        front_y,
        ego_speed,
        ego_station,
        vrus.started,
        vrus.started_at_s,
        vrus.station_m,
        vrus.speed_mps,
        vrus.kinematics,
        vrus.ego_stopped_at_s,
    )


@batch_kernel
def _advance(
    path,
    offsets,
    kind,
    value,
    point_x,
    point_y,
    top,
    max_accel,
    tau,
    initial_speed,
    brake_after,
    brake_decel,
    dt,
    t,
    front_x,
    front_y,
    ego_speed,
    ego_station,
    started,
    started_at,
    station,
    speed,
    kin,
    stopped_at,
):  # pragma: no cover
    for b in prange(station.shape[0]):
        point_mass_variant(
            b,
            path,
            offsets,
            kind,
            value,
            point_x,
            point_y,
            top,
            max_accel,
            tau,
            initial_speed,
            brake_after,
            brake_decel,
            dt,
            t,
            front_x,
            front_y,
            ego_speed,
            ego_station,
            started,
            started_at,
            station,
            speed,
            kin,
            stopped_at,
        )


@njit(cache=True, inline="always")
def point_mass_variant(
    b,
    path,
    offsets,
    kind,
    value,
    point_x,
    point_y,
    top,
    max_accel,
    tau,
    initial_speed,
    brake_after,
    brake_decel,
    dt,
    t,
    front_x,
    front_y,
    ego_speed,
    ego_station,
    started,
    started_at,
    station,
    speed,
    kin,
    stopped_at,
):  # pragma: no cover (compiled)
    """`_advance` for variant b."""
    K = station.shape[1]
    for k in range(K):
        step = dt
        if not started[b, k]:
            started[b, k], lead = fire_trigger(
                kind, value, point_x, point_y, b, k, t, front_x, front_y, ego_speed, ego_station, stopped_at
            )
            if started[b, k]:
                # start the profile where the trigger was met, not at the step boundary: back up to that
                # instant at the initial speed and integrate this step over dt + lead
                lead = min(max(lead, 0.0), dt)
                started_at[b, k] = t - lead
                station[b, k] -= speed[b, k] * lead
                step = dt + lead
        limit = max_accel[b, k]
        if not started[b, k]:
            target = initial_speed[b, k]
        elif t >= started_at[b, k] + brake_after[b, k] - 1e-9:
            target, limit = 0.0, brake_decel[b, k]
        else:
            target = top[b, k]
        accel = (target - speed[b, k]) / max(tau[b, k], step)
        accel = min(max(accel, -limit), limit)
        new_speed = speed[b, k] + accel * step
        station[b, k] += (speed[b, k] + new_speed) * 0.5 * step
        speed[b, k] = new_speed
        px, py, tx, ty, _ = locate_point(path, offsets[b, k], station[b, k])
        kin[0, b, k], kin[1, b, k], kin[2, b, k], kin[3, b, k] = px, py, new_speed * tx, new_speed * ty
        kin[4, b, k], kin[5, b, k] = accel * tx, accel * ty


attach_vru_step(POINT_MASS, advance_vrus)
