"""The speed profile that makes a VRU cover `d` metres in `T` seconds, in the shape vrusim's VRU kernel runs exactly.

vrusim's VRU (`vrusim.sim.vru.motion`, `speed_time_constant_s` 0) holds its initial speed v0 until its trigger,
then changes speed at a constant rate `max_accel_mps2` to `top_speed_mps` (up or down) and holds it. A profile
here is: hold v0 for `delay_s` after the action starts (a later trigger), one ramp to v_f, hold v_f.

- no final speed (esmini's reading of ASAM OpenSCENARIO 1.3, where the arrival speed is free): one constant
  acceleration over the whole time, v_f = 2 d / T - v0;
- a final speed v_f: the ramp starts at once and ends before the arrival,
  a = (v_f - v0)^2 / (2 (v_f T - d)); when even that arrives too early, v0 is held first and the ramp ends at
  the arrival;
- a final speed with a steady state of D m (or t s: D = v_f t): the ramp ends exactly D before the target, at
  T - D / v_f, after holding v0 as long as needed.

Anything else (a profile that would need two ramps, or to reverse) is a `ProfileError`, whose message the caller
puts at the element's line. Also here: the station of a target point on the VRU's path.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

SAME_SPEED_MPS = 1e-9
DISTANCE_TOL_M = 1e-6
"""A profile without a speed change must cover the distance within this, m."""
ON_PATH_M = 0.01
"""A target with tolerance 0 must lie within this distance of the path (it is projected onto it), m."""


class ProfileError(ValueError):
    """No profile of vrusim's shape fits; the message says why."""


@dataclass(frozen=True)
class Profile:
    """Hold the initial speed `delay_s` s, then change to `top_mps` at `rate_mps2` (None: no change) and hold it."""

    delay_s: float
    top_mps: float
    rate_mps2: float | None


def solve_profile(
    v0_mps: float, distance_m: float, time_s: float, final_mps: float | None, steady_m: float | None = None
) -> Profile:
    """The profile covering `distance_m` (> 0) in `time_s` (> 0) from `v0_mps`, arriving at `final_mps` (None:
    any) after a steady state of `steady_m` m at that speed (None: none)."""
    v0, d, t = v0_mps, distance_m, time_s
    if final_mps is None:
        final = 2.0 * d / t - v0
        if final < -SAME_SPEED_MPS:
            raise ProfileError(
                f"the VRU would have to stop and reverse: at a constant rate from {v0:g} m/s it covers {d:.3f} m "
                f"in {t:.3f} s only by ending at {final:.3f} m/s"
            )
        final = max(final, 0.0)
        return Profile(0.0, final, abs(final - v0) / t if abs(final - v0) > SAME_SPEED_MPS else None)
    if steady_m is not None:
        if final_mps <= 0.0:
            raise ProfileError("a steady state needs a final speed > 0")
        ramp_d, ramp_t = d - steady_m, t - steady_m / final_mps
        if ramp_d < -DISTANCE_TOL_M or ramp_t <= 0.0:
            raise ProfileError(
                f"the steady state ({steady_m:.3f} m, {steady_m / final_mps:.3f} s) is longer than the way to the "
                f"target ({d:.3f} m in {t:.3f} s)"
            )
        return _ramp_ending_at(v0, final_mps, max(ramp_d, 0.0), ramp_t)
    if abs(final_mps - v0) <= SAME_SPEED_MPS:
        return _ramp_ending_at(v0, final_mps, d, t)
    ramp_s = 2.0 * (final_mps * t - d) / (final_mps - v0)
    if 0.0 < ramp_s <= t * (1.0 + 1e-12):
        return Profile(0.0, final_mps, abs(final_mps - v0) / ramp_s)
    if ramp_s > t:
        return _ramp_ending_at(v0, final_mps, d, t)
    raise ProfileError(_two_ramps(v0, final_mps, d, t))


def _ramp_ending_at(v0: float, final: float, d: float, t: float) -> Profile:
    """Hold v0, then one ramp to `final` that ends exactly after `d` m and `t` s."""
    if abs(final - v0) <= SAME_SPEED_MPS:
        if abs(d - v0 * t) > DISTANCE_TOL_M:
            raise ProfileError(
                f"at its speed {v0:g} m/s, which is also the final speed, the VRU covers {v0 * t:.3f} m in "
                f"{t:.3f} s, not {d:.3f} m"
            )
        return Profile(0.0, final, None)
    delay = (d - 0.5 * (v0 + final) * t) / (0.5 * (v0 - final))
    if delay < -1e-9 * max(t, 1.0) or delay >= t * (1.0 - 1e-9):
        raise ProfileError(_two_ramps(v0, final, d, t))
    delay = max(delay, 0.0)
    return Profile(delay, final, abs(final - v0) / (t - delay))


def _two_ramps(v0: float, final: float, d: float, t: float) -> str:
    return (
        f"no single speed change from {v0:g} to {final:g} m/s covers {d:.3f} m in {t:.3f} s (mean "
        f"{d / t:.3f} m/s); vrusim's VRU changes its speed once"
    )


def path_station(
    start: tuple[float, float], points: list[tuple[float, float]], target: tuple[float, float], tolerance_m: float
) -> float | None:
    """The first station (m) of the path start -> points (then straight on) within `tolerance_m` of `target`
    (with a tolerance below `ON_PATH_M`: the target's projection, when within `ON_PATH_M`); None: never."""
    radius = max(tolerance_m, ON_PATH_M)
    station, previous = 0.0, start
    for index, point in enumerate(points):
        dx, dy = point[0] - previous[0], point[1] - previous[1]
        length = math.hypot(dx, dy)
        ux, uy = dx / length, dy / length
        wx, wy = target[0] - previous[0], target[1] - previous[1]
        along, off = wx * ux + wy * uy, abs(wx * uy - wy * ux)
        end = math.inf if index == len(points) - 1 else length
        if off <= radius:
            half = math.sqrt(radius * radius - off * off)
            entry = along if tolerance_m < ON_PATH_M else along - half
            if along + half >= 0.0 and entry <= end:
                return station + max(entry, 0.0)
        station, previous = station + length, point
    return None
