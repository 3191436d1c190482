"""Numba kernel of the realistic V2X channel: one step of RSU message generation, link, delivery and ego tracks.

Per (variant b, VRU k) the RSU decides whether to generate a message (`MODE_*` rule), the link decides whether
it gets through (loss model, range, outages) and when (latency + jitter), a FIFO ring buffer holds it until
then, and the ego keeps a track from the newest message delivered. Random draws come from `vrusim.sim.rng`,
keyed by (seed, generation step, stream, VRU slot): a variant's channel never depends on its batch.
"""

from __future__ import annotations

import math

from vrusim.kernels import batch_kernel, njit, prange
from vrusim.sim.rng import STREAM_RSU_NOISE, STREAM_V2X_JITTER, normal, uniform
from vrusim.sim.v2x.loss import bernoulli, distance, gilbert_elliott, none
from vrusim.sim.v2x.loss.registry import PLUGIN_CODE

MODE_EVERY_STEP, MODE_PERIODIC, MODE_ETSI_VAM = 0, 1, 2
LOSS_NONE, LOSS_BERNOULLI, LOSS_GILBERT_ELLIOTT, LOSS_DISTANCE = (
    none.CODE,
    bernoulli.CODE,
    gilbert_elliott.CODE,
    distance.CODE,
)
LOSS_PLUGIN = PLUGIN_CODE
"""Loss-model codes at or above this are plug-ins, decided before the kernel (`external_lost`)."""

# columns of the per-variant configuration array cfg [B, N_CFG]
CFG_PERIOD_STEPS = 0  # periodic: 1 / (rate_hz dt)
CFG_VAM_MIN_STEPS = 1  # etsi_vam: T_GenVamMin / dt
CFG_VAM_MAX_STEPS = 2  # etsi_vam: T_GenVamMax / dt
CFG_VAM_POSITION_M = 3
CFG_VAM_SPEED_MPS = 4
CFG_VAM_COS_HEADING = 5  # cos of the heading threshold
CFG_LATENCY_S = 6
CFG_JITTER_S = 7
CFG_POSITION_SIGMA_M = 8
CFG_SPEED_SIGMA_MPS = 9
CFG_MAX_AGE_S = 10
N_CFG = 11
# the loss model's parameters are in their own array loss_params [B, P] (each model's `pack`: sim/v2x/loss/)

_STEP_TOLERANCE = 1e-6
"""Tolerance of step-count comparisons (intervals in steps are real numbers)."""
_TIME_TOLERANCE = 1e-9
"""Tolerance of time comparisons, s (n dt is not exact in binary)."""


@njit(cache=True, inline="always")
def _wants_message(n, b, k, mode, cfg, last_gen, due, forced, ref, kin):  # pragma: no cover (compiled)
    """Whether the RSU generates a message about covered VRU k of variant b at step n."""
    if mode == MODE_EVERY_STEP:
        return True
    if mode == MODE_PERIODIC:
        return n >= due[b, k] - _STEP_TOLERANCE
    if last_gen[b, k] < 0:
        return True
    elapsed = n - last_gen[b, k]
    if elapsed < cfg[b, CFG_VAM_MIN_STEPS] - _STEP_TOLERANCE:
        return False
    if forced or elapsed >= cfg[b, CFG_VAM_MAX_STEPS] - _STEP_TOLERANCE:
        return True
    dx, dy = kin[0, b, k] - ref[b, k, 0], kin[1, b, k] - ref[b, k, 1]
    threshold = cfg[b, CFG_VAM_POSITION_M]
    if dx * dx + dy * dy >= threshold * threshold:
        return True
    vx, vy, rvx, rvy = kin[2, b, k], kin[3, b, k], ref[b, k, 2], ref[b, k, 3]
    speed, ref_speed = math.sqrt(vx * vx + vy * vy), math.sqrt(rvx * rvx + rvy * rvy)
    if abs(speed - ref_speed) >= cfg[b, CFG_VAM_SPEED_MPS]:
        return True
    return speed > 0.0 and ref_speed > 0.0 and vx * rvx + vy * rvy <= cfg[b, CFG_VAM_COS_HEADING] * speed * ref_speed


@njit(cache=True, inline="always")
def _lost(n, b, k, seed, loss_model, loss_params, link_state, link_distance, external_lost):  # pragma: no cover
    """Whether the message of VRU k generated at step n is lost (each built-in model: sim/v2x/loss/<model>.py)."""
    if loss_model == LOSS_BERNOULLI:
        return bernoulli.lost(n, b, k, seed, loss_params, link_state, link_distance)
    if loss_model == LOSS_GILBERT_ELLIOTT:
        return gilbert_elliott.lost(n, b, k, seed, loss_params, link_state, link_distance)
    if loss_model == LOSS_DISTANCE:
        return distance.lost(n, b, k, seed, loss_params, link_state, link_distance)
    if loss_model >= LOSS_PLUGIN:
        return external_lost[b, k]
    return False


@njit(cache=True, inline="always")
def _in_outage(t, b, outage_start, outage_end, outage_count):  # pragma: no cover (compiled)
    for i in range(outage_count[b]):
        if outage_start[b, i] - _TIME_TOLERANCE <= t < outage_end[b, i] - _TIME_TOLERANCE:
            return True
    return False


@njit(cache=True, inline="always")
def _slot(head, j, capacity):  # pragma: no cover (compiled)
    """Ring-buffer slot j places after `head` (head in [0, capacity), j in [0, capacity]): (head + j) % capacity
    without a division."""
    i = head + j
    return i - capacity if i >= capacity else i


@njit(cache=True, inline="always")
def _push(
    n, due_step, b, k, seed, cfg, kin, buf_gen, buf_due, buf_kin, buf_head, buf_count
):  # pragma: no cover (compiled)
    """Queue the RSU's report of VRU k (with its perception error) for delivery at `due_step`."""
    capacity = buf_gen.shape[2]
    count = buf_count[b, k]
    if count == capacity:  # cannot happen with the capacity chosen by the channel; drop the oldest
        buf_head[b, k] = _slot(buf_head[b, k], 1, capacity)
        count -= 1
    i = _slot(buf_head[b, k], count, capacity)
    buf_gen[b, k, i] = n
    buf_due[b, k, i] = due_step
    for row in range(6):
        buf_kin[b, k, i, row] = kin[row, b, k]
    sigma = cfg[b, CFG_POSITION_SIGMA_M]
    if sigma > 0.0:
        buf_kin[b, k, i, 0] += sigma * normal(seed, n, STREAM_RSU_NOISE, 4 * k)
        buf_kin[b, k, i, 1] += sigma * normal(seed, n, STREAM_RSU_NOISE, 4 * k + 1)
    sigma = cfg[b, CFG_SPEED_SIGMA_MPS]
    if sigma > 0.0:
        buf_kin[b, k, i, 2] += sigma * normal(seed, n, STREAM_RSU_NOISE, 4 * k + 2)
        buf_kin[b, k, i, 3] += sigma * normal(seed, n, STREAM_RSU_NOISE, 4 * k + 3)
    buf_count[b, k] = count + 1


@njit(cache=True, inline="always")
def _take_newest_due(
    n, b, k, ordered, buf_gen, buf_due, buf_kin, buf_head, buf_count, track_gen, track_kin, delivered
):  # pragma: no cover (compiled)
    """Deliver the newest queued message due by step n; older queued ones are dropped (already superseded).

    `ordered`: the queue's due steps never decrease (no jitter: every message waits the same whole steps), so the
    scan stops at the first message not yet due; every later one is not due either.
    """
    capacity = buf_gen.shape[2]
    head, count = buf_head[b, k], buf_count[b, k]
    newest = -1
    for j in range(count):
        if buf_due[b, k, _slot(head, j, capacity)] <= n:
            newest = j
        elif ordered:
            break
    if newest >= 0:
        i = _slot(head, newest, capacity)
        track_gen[b, k] = buf_gen[b, k, i]
        for row in range(6):
            track_kin[b, k, row] = buf_kin[b, k, i, row]
        buf_head[b, k] = _slot(head, newest + 1, capacity)
        buf_count[b, k] = count - newest - 1
        delivered[b, k] += 1


@batch_kernel
def channel_step(
    n,
    dt,
    seed,
    mode,
    loss_model,
    cfg,
    loss_params,
    outage_start,
    outage_end,
    outage_count,
    covered,
    in_range,
    kin,
    link_distance,
    last_gen,
    due,
    force,
    ref,
    was_covered,
    link_state,
    buf_gen,
    buf_due,
    buf_kin,
    buf_head,
    buf_count,
    track_gen,
    track_kin,
    generated,
    delivered,
    external_lost,
    received,
    out_kin,
    age,
):  # pragma: no cover (compiled)
    """Advance the channel of every variant to step n and write what each ego knows (received, out_kin, age)."""
    settings = (seed, mode, loss_model, cfg, loss_params, outage_start, outage_end, outage_count)
    state = (
        last_gen, due, force, ref, was_covered, link_state, buf_gen, buf_due, buf_kin, buf_head, buf_count,
        track_gen, track_kin, generated, delivered, external_lost,
    )  # fmt: skip
    for b in prange(covered.shape[0]):
        channel_variant(b, n, dt, settings, state, covered, in_range, kin, link_distance, received, out_kin, age)


@njit(cache=True, inline="always")
def channel_variant(
    b, n, dt, settings, state, covered, in_range, kin, link_distance, received, out_kin, age
):  # pragma: no cover (compiled)
    """`channel_step` for variant b; `settings` and `state` are the channel's arrays in `channel_step`'s order
    (grouped: inlined into the compiled step, which a call of some 30 arrays would slow by about a third)."""
    seed, mode, loss_model, cfg, loss_params, outage_start, outage_end, outage_count = settings
    (
        last_gen, due, force, ref, was_covered, link_state, buf_gen, buf_due, buf_kin, buf_head, buf_count,
        track_gen, track_kin, generated, delivered, external_lost,
    ) = state  # fmt: skip
    K = covered.shape[1]
    t = n * dt
    ordered = not cfg[b, CFG_JITTER_S] > 0.0
    for k in range(K):
        if covered[b, k]:
            if not was_covered[b, k]:
                force[b, k] = True
            if _wants_message(n, b, k, mode[b], cfg, last_gen, due, force[b, k], ref, kin):
                generated[b, k] += 1
                last_gen[b, k] = n
                force[b, k] = False
                for row in range(4):
                    ref[b, k, row] = kin[row, b, k]
                # periodic schedule: the next slot, or a fresh start after a skipped slot (VRU not covered)
                on_time = n < due[b, k] + 1.0 - _STEP_TOLERANCE
                due[b, k] = (due[b, k] if on_time else n) + cfg[b, CFG_PERIOD_STEPS]
                lost = _lost(n, b, k, seed[b], loss_model[b], loss_params, link_state, link_distance[b], external_lost)
                if in_range[b, k] and not lost:
                    delay = cfg[b, CFG_LATENCY_S]
                    if cfg[b, CFG_JITTER_S] > 0.0:
                        delay += cfg[b, CFG_JITTER_S] * uniform(seed[b], n, STREAM_V2X_JITTER, k)
                    due_step = n + math.ceil(delay / dt - _TIME_TOLERANCE)
                    if not (
                        _in_outage(t, b, outage_start, outage_end, outage_count)
                        or _in_outage(due_step * dt, b, outage_start, outage_end, outage_count)
                    ):
                        _push(n, due_step, b, k, seed[b], cfg, kin, buf_gen, buf_due, buf_kin, buf_head, buf_count)
        was_covered[b, k] = covered[b, k]
        _take_newest_due(
            n, b, k, ordered, buf_gen, buf_due, buf_kin, buf_head, buf_count, track_gen, track_kin, delivered
        )
        g = track_gen[b, k]
        if g >= 0 and (n - g) * dt > cfg[b, CFG_MAX_AGE_S] + _TIME_TOLERANCE:
            track_gen[b, k] = -1
            g = -1
        if g < 0:  # nothing known: pass the sent values on unread, as the ideal channel does
            received[b, k] = False
            age[b, k] = 0.0
            for row in range(6):
                out_kin[row, b, k] = kin[row, b, k]
            continue
        a = (n - g) * dt
        received[b, k] = True
        age[b, k] = a
        for row in range(6):
            out_kin[row, b, k] = track_kin[b, k, row]
        if n > g:  # constant-velocity prediction over the message's age
            out_kin[0, b, k] += track_kin[b, k, 2] * a
            out_kin[1, b, k] += track_kin[b, k, 3] * a


@batch_kernel
def generation_mask(n, mode, cfg, covered, was_covered, last_gen, due, force, ref, kin, out):  # pragma: no cover
    """Which messages `channel_step` will generate at step n (out [B, K]), without changing any state: what
    plug-in loss models decide on before the kernel runs."""
    B, K = covered.shape
    for b in prange(B):
        for k in range(K):
            forced = force[b, k] or not was_covered[b, k]
            out[b, k] = covered[b, k] and _wants_message(n, b, k, mode[b], cfg, last_gen, due, forced, ref, kin)
