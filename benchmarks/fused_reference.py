"""The denominator of issue 20: a hand-written, fused Numba kernel of the paper's pedestrian workload, timed in the
same process as vrusim's engine on the same batch.

Run: python benchmarks/fused_reference.py [--batch 10000] [--steps 1000] [--repeats 3]

The workload is `bench_engine.packed_batch`: the paper pedestrian case (He et al., CPSI 2025, case (i)) with V2X on,
stop rules off and the ego's cruise speed spread over 12–18 m/s, stepped `--steps` times at dt 0.01 s. The
reference does the same physics per variant and step, all in one compiled loop (parallel over variants, state in
registers, no temporaries, no early stop):

- ego: kinematic bicycle tracking its straight route (lateral and heading feedback), the planner's command
  clipped, through a first-order actuator lag and a jerk limit, exact constant-acceleration position update;
- pedestrian: point mass along its straight path, standing until its trigger, then constant acceleration to its
  top speed;
- sensing: the sector sensor (range, field of view from the front bumper) and V2X awareness (the pedestrian
  inside the RSU's coverage, the ego inside its communication range);
- planner: the FSM's two-stage braking: a detected pedestrian whose crossing window overlaps the ego's occupancy
  of the conflict zone starts Pre-Slow, Emergency-Brake within D_safe = headway · v, held until it has cleared;
- contact: the exact clearance between the ego rectangle and the pedestrian circle, and the time to collision
  along the ego's heading; accumulators: minimum clearance and TTC, first contact time.

It is a simplification of what vrusim computes (no sensor or channel models, no tracks, no trace, no stop rules,
one VRU): the throughput a specialised program reaches on this machine, the figure vrusim's general engine is
measured against. `--check` compares its outcomes (contact or not, first contact time) with vrusim's on the
same batch, so that the two really do the same work.
"""

from __future__ import annotations

import math
import sys
import time
from pathlib import Path

import numpy as np
from numba import njit, prange

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_engine import packed_batch, shortened  # the same batch as the engine benchmark
from machine import kernel_options

# paper pedestrian case, fixed for every variant (m, s, m/s, m/s^2)
EGO_HALF_LENGTH_M, EGO_HALF_WIDTH_M, REAR_TO_CENTRE_M = 2.25, 0.9, 1.35
EGO_Y_M, EGO_START_X_M = -1.75, -50.0
MAX_ACCEL, MAX_DECEL, LAG_S, MAX_JERK = 2.0, 6.0, 0.1, 20.0
K_LATERAL, K_HEADING = 0.3, 1.2
PED_X_M, PED_Y_M, PED_TOP_MPS, PED_ACCEL_MPS2, PED_RADIUS_M, PED_TRIGGER_S = 18.0, -10.0, 1.8, 1.0, 0.5, 0.3
SENSOR_RANGE_M, SENSOR_HALF_FOV_RAD = 20.0, math.radians(60.0)
RSU_X_M, RSU_Y_M, COMM_RANGE_M, COVERAGE_M = 22.0, 4.0, 41.0, 20.0
HEADWAY_S, PRE_SLOW, EMERGENCY, CRUISE_ACCEL, CRUISE_GAIN = 2.0, 2.0, 6.0, 1.5, 0.8
MARGIN_M, TIME_MARGIN_S, ARRIVAL_MIN_MPS = 0.25, 1.0, 1.0


@njit(cache=True, inline="always")
def time_to_cover(distance_m, speed_mps, accel_mps2):  # pragma: no cover (compiled)
    """Time to cover `distance_m` > 0 from `speed_mps` under constant `accel_mps2` >= 0, s (inf: never)."""
    if accel_mps2 > 0.0:
        return (math.sqrt(speed_mps * speed_mps + 2.0 * accel_mps2 * distance_m) - speed_mps) / accel_mps2
    return distance_m / speed_mps if speed_mps > 0.0 else np.inf


@njit(parallel=True, cache=True, fastmath=False)
def fused_pedestrian(cruise_mps, n_steps, dt, min_clearance, min_ttc, contact_s):  # pragma: no cover (compiled)
    """Step every variant `n_steps` times; write its minimum clearance (m), minimum TTC (s) and first contact
    time (s; inf: none)."""
    for b in prange(cruise_mps.shape[0]):
        # ego (rear axle), heading unit vector, speed, acceleration, actuator state, planner mode
        x, y, hx, hy = EGO_START_X_M - REAR_TO_CENTRE_M, EGO_Y_M, 1.0, 0.0
        v, act, mode = cruise_mps[b], 0.0, 0
        # pedestrian along +y
        py, pv, started = PED_Y_M, 0.0, False
        clear_min, ttc_min, first = np.inf, np.inf, np.inf
        for step in range(n_steps):
            t = step * dt
            cx, cy = x + REAR_TO_CENTRE_M * hx, y + REAR_TO_CENTRE_M * hy
            fx, fy = cx + EGO_HALF_LENGTH_M * hx, cy + EGO_HALF_LENGTH_M * hy
            # sensing: sector from the front bumper, or V2X from the RSU
            dx, dy = PED_X_M - fx, py - fy
            distance = math.sqrt(dx * dx + dy * dy)
            seen = distance <= SENSOR_RANGE_M and (dx * hx + dy * hy) >= distance * math.cos(SENSOR_HALF_FOV_RAD)
            rx, ry = PED_X_M - RSU_X_M, py - RSU_Y_M
            ex, ey = cx - RSU_X_M, cy - RSU_Y_M
            heard = rx * rx + ry * ry <= COVERAGE_M * COVERAGE_M and ex * ex + ey * ey <= COMM_RANGE_M * COMM_RANGE_M
            # planner: two-stage braking on a conflicting pedestrian
            command = CRUISE_GAIN * (cruise_mps[b] - v)
            command = min(max(command, -PRE_SLOW), CRUISE_ACCEL)
            conflict = False
            if seen or heard:
                ahead = dx * hx + dy * hy
                lateral = -dx * hy + dy * hx
                reach = EGO_HALF_WIDTH_M + PED_RADIUS_M + MARGIN_M
                if ahead > -2.0 * EGO_HALF_LENGTH_M:
                    arrival = max(ahead, 0.0) / max(v, ARRIVAL_MIN_MPS)
                    leave = arrival + (2.0 * EGO_HALF_LENGTH_M + 2.0 * EGO_HALF_WIDTH_M) / max(v, ARRIVAL_MIN_MPS)
                    pa = PED_ACCEL_MPS2 if started and pv < PED_TOP_MPS else 0.0  # setting off: keeps speeding up
                    if abs(lateral) <= reach:
                        enter, exit_ = 0.0, time_to_cover(reach - lateral, pv, pa)
                    elif lateral < 0.0:
                        enter, exit_ = time_to_cover(-reach - lateral, pv, pa), time_to_cover(reach - lateral, pv, pa)
                    else:
                        enter, exit_ = np.inf, np.inf
                    conflict = enter <= leave + TIME_MARGIN_S and exit_ >= arrival - TIME_MARGIN_S
                # once slowing, Cruise again only when the pedestrian has cleared the path
                conflict = conflict or (mode != 0 and lateral <= reach and ahead > -2.0 * EGO_HALF_LENGTH_M)
                if conflict:
                    gap = ahead - PED_RADIUS_M
                    if mode == 2 or gap < HEADWAY_S * v:
                        mode, command = 2, -EMERGENCY
                    else:
                        mode, command = 1, -PRE_SLOW
            if not conflict:
                mode = 0
            # pedestrian motion
            if not started and t >= PED_TRIGGER_S - 1e-9:
                started = True
            if started:
                pv_new = min(pv + PED_ACCEL_MPS2 * dt, PED_TOP_MPS)
                py += (pv + pv_new) * 0.5 * dt
                pv = pv_new
            # ego: straight route along y = EGO_Y_M; bicycle with feedback, lag, jerk limit
            lateral_error = y - EGO_Y_M
            turn_rate = -K_LATERAL * lateral_error - K_HEADING * hy
            wanted = min(max(command, -MAX_DECEL), MAX_ACCEL)
            wanted = act + (wanted - act) * min(dt / LAG_S, 1.0)
            act += min(max(wanted - act, -MAX_JERK * dt), MAX_JERK * dt)
            v_new = v + act * dt
            if v_new < 0.0:
                travelled = v * v / (2.0 * max(-act, 1e-12))
                v_new = 0.0
            else:
                travelled = (v + v_new) * 0.5 * dt
            turn = turn_rate * travelled
            c, s = math.cos(0.5 * turn), math.sin(0.5 * turn)
            x += travelled * (c * hx - s * hy)
            y += travelled * (s * hx + c * hy)
            c, s = math.cos(turn), math.sin(turn)
            hx, hy = c * hx - s * hy, s * hx + c * hy
            v = v_new
            # contact: rectangle – circle clearance, TTC along the heading
            cx, cy = x + REAR_TO_CENTRE_M * hx, y + REAR_TO_CENTRE_M * hy
            qx, qy = PED_X_M - cx, py - cy
            lon, lat = qx * hx + qy * hy, -qx * hy + qy * hx
            ox = max(abs(lon) - EGO_HALF_LENGTH_M, 0.0)
            oy = max(abs(lat) - EGO_HALF_WIDTH_M, 0.0)
            if ox > 0.0 or oy > 0.0:
                clearance = math.sqrt(ox * ox + oy * oy) - PED_RADIUS_M
            else:
                clearance = -min(EGO_HALF_LENGTH_M - abs(lon), EGO_HALF_WIDTH_M - abs(lat)) - PED_RADIUS_M
            clear_min = min(clear_min, clearance)
            if clearance <= 0.0 and first == np.inf:
                first = t + dt
            if v > 0.0 and lon > EGO_HALF_LENGTH_M and abs(lat) <= EGO_HALF_WIDTH_M + PED_RADIUS_M:
                ttc_min = min(ttc_min, (lon - EGO_HALF_LENGTH_M - PED_RADIUS_M) / v)
        min_clearance[b], min_ttc[b], contact_s[b] = clear_min, ttc_min, first


def run_reference(cruise_mps: np.ndarray, n_steps: int, dt: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Run the fused kernel; (minimum clearance m, minimum TTC s, first contact s) per variant."""
    out = [np.empty(cruise_mps.size) for _ in range(3)]
    fused_pedestrian(cruise_mps, n_steps, dt, *out)
    return out[0], out[1], out[2]


def best_time(function, repeats: int) -> float:
    """Fastest wall time of `repeats` calls, s."""
    best = math.inf
    for _ in range(repeats):
        start = time.perf_counter()
        function()
        best = min(best, time.perf_counter() - start)
    return best


def main() -> None:
    parser = kernel_options(__doc__.splitlines()[0], batch=10_000, repeats=3, json_output=False)
    parser.add_argument("--check", action="store_true", help="compare outcomes with vrusim's")
    args = parser.parse_args()
    from vrusim.engine.simulate import simulate

    dt = 0.01
    params = packed_batch(args.batch, args.steps * dt)
    cruise = np.ascontiguousarray(params.cruise_speed_mps)
    run_reference(cruise[:2], 2, dt)  # compile / load from cache
    reference_s = best_time(lambda: run_reference(cruise, args.steps, dt), args.repeats)
    simulate(shortened(params, 2))  # load the compiled kernels this batch size uses
    result = None

    def engine() -> None:
        nonlocal result
        result = simulate(params)

    engine_s = best_time(engine, args.repeats)
    work = args.batch * args.steps
    rows = [("fused reference kernel", reference_s), ("vrusim engine (fsm)", engine_s)]
    print(f"B = {args.batch:,}, {args.steps:,} steps, best of {args.repeats}")
    print(f"{'':26s} {'wall s':>8s} {'M scenario-steps/s':>20s}")
    for name, seconds in rows:
        print(f"{name:26s} {seconds:8.3f} {work / seconds / 1e6:20.1f}")
    print(f"vrusim / reference: {reference_s / engine_s:.1%}")
    if args.check and result is not None:
        from vrusim.engine.accumulators import MIN_CLR

        clearance, _, contact = run_reference(cruise, args.steps, dt)
        ours = result.metrics.values[MIN_CLR]
        print(f"contacts: reference {np.isfinite(contact).sum()}, vrusim {int(result.metrics.collided.sum())}")
        print(
            f"minimum clearance, m (min / median / max): reference {np.min(clearance):.2f} / "
            f"{np.median(clearance):.2f} / {np.max(clearance):.2f}, vrusim {np.min(ours):.2f} / "
            f"{np.median(ours):.2f} / {np.max(ours):.2f}"
        )


if __name__ == "__main__":
    main()
