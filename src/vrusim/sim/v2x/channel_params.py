"""Each variant's V2X channel spec packed into arrays (`ChannelParams`): generation, delay, loss, outages.

Specs shared by several variants are packed once. After packing, the channel reads only these arrays.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from vrusim.scenario.schema import Scenario
from vrusim.scenario.v2x import ChannelSpec
from vrusim.sim.sensing.sensor_params import MAX_WHOLE_STEPS
from vrusim.sim.v2x import kernels as kern
from vrusim.sim.v2x.loss.registry import loss_entry

_MODES = {"every_step": kern.MODE_EVERY_STEP, "periodic": kern.MODE_PERIODIC, "etsi_vam": kern.MODE_ETSI_VAM}


def channel_config(spec: ChannelSpec, dt_s: float) -> tuple[int, int, np.ndarray, tuple[float, ...]]:
    """(generation mode, loss model code, cfg row [N_CFG], loss parameters) of one variant's channel."""
    gen, loss = spec.generation, spec.loss
    row = np.zeros(kern.N_CFG)
    row[kern.CFG_PERIOD_STEPS] = 1.0 / (gen.rate_hz * dt_s) if gen.mode == "periodic" else 0.0
    row[kern.CFG_VAM_MIN_STEPS] = gen.vam_min_interval_s / dt_s
    row[kern.CFG_VAM_MAX_STEPS] = gen.vam_max_interval_s / dt_s
    row[kern.CFG_VAM_POSITION_M] = gen.vam_position_change_m
    row[kern.CFG_VAM_SPEED_MPS] = gen.vam_speed_change_mps
    row[kern.CFG_VAM_COS_HEADING] = math.cos(math.radians(gen.vam_heading_change_deg))
    row[kern.CFG_LATENCY_S] = spec.latency_s
    row[kern.CFG_JITTER_S] = spec.jitter_s
    row[kern.CFG_POSITION_SIGMA_M] = spec.rsu_position_sigma_m
    row[kern.CFG_SPEED_SIGMA_MPS] = spec.rsu_speed_sigma_mps
    row[kern.CFG_MAX_AGE_S] = spec.track_max_age_s
    entry = loss_entry(loss)
    return _MODES[gen.mode], entry.code, row, tuple(float(v) for v in entry.pack(loss))


def queue_capacity(spec: ChannelSpec, dt_s: float) -> int:
    """Most messages of one VRU in flight at once, plus one: floor(max delay / min interval) + 2 (in steps); the
    channel allocates at most the run's steps + 2 of them."""
    gen = spec.generation
    max_delay = math.ceil(min((spec.latency_s + spec.jitter_s) / dt_s - 1e-9, MAX_WHOLE_STEPS))
    interval = {"every_step": 1.0, "periodic": 1.0 / (gen.rate_hz * dt_s), "etsi_vam": gen.vam_min_interval_s / dt_s}
    min_interval = max(1, math.floor(interval[gen.mode] - 1e-6))
    return max_delay // min_interval + 2


def queue_slots(capacity: np.ndarray, n_steps: int) -> int:
    """Slots of the channel's message queue for a run of `n_steps`: the largest `queue_capacity`, but at most the
    run's steps + 2, since a VRU sends at most one message a step (so the queue never fills either way)."""
    return int(min(int(capacity.max()), max(n_steps, 1) + 2))


@dataclass(frozen=True)
class ChannelParams:
    """V2X channel settings per variant (first axis B)."""

    ideal: np.ndarray
    """Whether the variant needs no realistic channel (V2X off, or an ideal channel spec), bool [B]."""
    mode: np.ndarray
    """Message generation mode (`kernels.MODE_*`), int8 [B]."""
    loss_model: np.ndarray
    """Loss model code (`vrusim.sim.v2x.loss.registry`), int8 [B]."""
    cfg: np.ndarray
    """Generation, delay, RSU noise and track age settings [B, kernels.N_CFG] (`kernels.CFG_*` columns)."""
    loss_params: np.ndarray
    """The loss model's packed parameters [B, P] (zero-padded)."""
    outage_start_s: np.ndarray
    """Outage start times [B, O] (zero-padded to the most outages of a variant), s."""
    outage_end_s: np.ndarray
    """Outage end times [B, O], s."""
    outage_count: np.ndarray
    """Outages of each variant, int64 [B]."""
    queue_capacity: np.ndarray
    """Messages of one VRU in flight at once, plus one (`queue_capacity`), int64 [B]."""


def pack_channel(scenarios: Sequence[Scenario], dt_s: float) -> ChannelParams:
    """The V2X channel settings of `scenarios` (time step `dt_s`), one row per scenario. Each distinct spec is
    packed once and its row copied to the variants that use it (a spec object is often shared by many)."""
    specs: list[ChannelSpec] = []  # the distinct specs, in order of first use
    position: dict[ChannelSpec, int] = {}
    by_object: dict[int, int] = {}
    variant_row = np.empty(len(scenarios), dtype=np.int64)
    enabled = np.empty(len(scenarios), dtype=bool)
    for b, scenario in enumerate(scenarios):
        v2x = scenario.v2x
        spec = v2x.channel_spec
        row = by_object.get(id(spec))
        if row is None:
            row = position.get(spec)
            if row is None:
                row = position[spec] = len(specs)
                specs.append(spec)
            by_object[id(spec)] = row
        variant_row[b], enabled[b] = row, v2x.enabled
    configs = [channel_config(spec, dt_s) for spec in specs]
    loss_params = np.zeros((len(specs), max(1, *(len(c[3]) for c in configs))))
    most = max(len(spec.outages) for spec in specs)
    outage_start, outage_end = np.zeros((len(specs), most)), np.zeros((len(specs), most))
    for row, (spec, config) in enumerate(zip(specs, configs, strict=True)):
        loss_params[row, : len(config[3])] = config[3]
        for i, outage in enumerate(spec.outages):
            outage_start[row, i], outage_end[row, i] = outage.start_s, outage.end_s
    ideal = np.array([spec.is_ideal for spec in specs], dtype=bool)
    return ChannelParams(
        ideal=~enabled | ideal[variant_row],
        mode=np.array([c[0] for c in configs], dtype=np.int8)[variant_row],
        loss_model=np.array([c[1] for c in configs], dtype=np.int8)[variant_row],
        cfg=np.stack([c[2] for c in configs])[variant_row],
        loss_params=loss_params[variant_row],
        outage_start_s=outage_start[variant_row],
        outage_end_s=outage_end[variant_row],
        outage_count=np.array([len(spec.outages) for spec in specs], dtype=np.int64)[variant_row],
        queue_capacity=np.array([queue_capacity(spec, dt_s) for spec in specs], dtype=np.int64)[variant_row],
    )
