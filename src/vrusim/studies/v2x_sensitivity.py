"""Sensitivity of a scenario's outcome to V2X latency and packet loss: collision probability per value.

Every value of the swept parameter runs `seeds` seeded variants of the base scenario (V2X on) in one batch;
the result per value is the collision probability with its Wilson 95 % interval. The *flip* of a sweep is
the first value at which the collision probability reaches one half; *onset* the first with any collision.
Channel settings besides the swept one: 10 Hz periodic messages, no jitter, no RSU error, tracks kept for
1 s beyond the latency (so a late message is still used).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from vrusim.engine.simulate import simulate
from vrusim.metrics.summary import summary_rows
from vrusim.planners.registry import make_planner
from vrusim.scenario.schema import Scenario
from vrusim.studies.compare import wilson_interval

BURST_EXIT_PROBABILITY = 0.2
"""Gilbert–Elliott sweeps: P(bad → good) per message, so bad runs last 5 messages (0.5 s at 10 Hz) on average."""
MAX_BURSTY_LOSS = 1.0 / (1.0 + BURST_EXIT_PROBABILITY)
"""Largest stationary loss with that mean bad run (p_good_to_bad = 1): 0.833."""
BASE_LATENCY_S = 0.1
"""Latency of the loss sweeps, s (the `typical` profile's)."""


def channel_for(kind: str, value: float) -> dict:
    """The channel specification of one sweep point: kind "latency" (s), "bernoulli" or "bursty" (loss)."""
    latency = value if kind == "latency" else BASE_LATENCY_S
    spec: dict = {"generation": {"mode": "periodic", "rate_hz": 10.0}, "latency_s": latency}
    spec["track_max_age_s"] = latency + 1.0
    if kind == "bernoulli" and value > 0:
        spec["loss"] = {"model": "bernoulli", "probability": value}
    elif kind == "bursty" and value > 0:
        # stationary loss = p_gb / (p_gb + p_bg) with loss 0 in the good and 1 in the bad state
        p_gb = value * BURST_EXIT_PROBABILITY / (1.0 - value) if value < 1.0 else float("inf")
        if p_gb > 1.0:
            raise ValueError(f"bursty loss {value} exceeds {MAX_BURSTY_LOSS:.3f}, the most that bad runs of mean "
                             f"length {1 / BURST_EXIT_PROBABILITY:g} messages allow")  # fmt: skip
        spec["loss"] = {
            "model": "gilbert_elliott",
            "p_good_to_bad": p_gb,
            "p_bad_to_good": BURST_EXIT_PROBABILITY,
            "loss_good": 0.0,
            "loss_bad": 1.0,
        }
    elif kind not in ("latency", "bernoulli", "bursty"):
        raise ValueError(f"unknown sweep kind {kind!r}")
    return spec


@dataclass(frozen=True)
class SweepPoint:
    """Collision probability at one value of the swept parameter."""

    value: float
    collisions: int
    runs: int

    @property
    def probability(self) -> float:
        return self.collisions / self.runs

    @property
    def interval(self) -> tuple[float, float]:
        return wilson_interval(self.collisions, self.runs)


def sweep(base: Scenario, kind: str, values: Sequence[float], seeds: int, planner: str = "fsm") -> list[SweepPoint]:
    """Collision probability of `base` (V2X on, `planner`) at every value, over `seeds` seeds each."""
    if seeds < 1:
        raise ValueError("seeds must be at least 1")
    scenarios = []
    for value in values:
        channel = channel_for(kind, value)
        for seed in range(seeds):
            data = base.model_dump()
            data["v2x"].update(enabled=True, channel=channel)
            if planner != base.planner.name:  # the file's parameters belong to its own planner
                data["planner"] = {"name": planner, "params": {}}
            data["sim"]["seed"] = seed
            scenarios.append(Scenario.model_validate(data))
    rows = summary_rows(simulate(scenarios, planner=make_planner(planner)))
    return [
        SweepPoint(value, sum(r["collided"] for r in rows[i * seeds : (i + 1) * seeds]), seeds)
        for i, value in enumerate(values)
    ]


def flip(points: list[SweepPoint], level: float = 0.5) -> float | None:
    """The first swept value whose collision probability reaches `level` (None: never)."""
    return next((p.value for p in points if p.probability >= level), None)


def onset(points: list[SweepPoint]) -> float | None:
    """The first swept value with any collision (None: never)."""
    return next((p.value for p in points if p.collisions > 0), None)
