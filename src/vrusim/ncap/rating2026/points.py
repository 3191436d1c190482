"""Cell colours -> scenario points (FC26 §5.3, LSC26 scoring as R26 computes it)."""

from __future__ import annotations

from collections.abc import Collection, Sequence
from dataclasses import dataclass

from vrusim.errors import UserInputError
from vrusim.ncap.rating2026 import tables as t


@dataclass(frozen=True)
class ScenarioPoints:
    """Points of one scenario by range, from predicted (or simulated) cell colours, before verification."""

    scenario: str
    standard: float
    extended: float
    robustness: float
    n_standard: int
    n_extended: int

    @property
    def total(self) -> float:
        return self.standard + self.extended + self.robustness

    def to_dict(self) -> dict[str, float | int | str]:
        return {
            "scenario": self.scenario,
            "standard": self.standard,
            "extended": self.extended,
            "robustness": self.robustness,
            "total": self.total,
            "n_standard": self.n_standard,
            "n_extended": self.n_extended,
        }


def extended_step(points: float, total: float) -> float:
    """Extended-range points snapped to 0 / 50 / 75 / 100 % of the range's total (FC26 §5.3.2)."""
    if total <= 0:
        return 0.0
    share = round(points / total, 6)
    for reached, awarded in t.EXTENDED_STEPS:
        if share >= reached:
            return awarded * total
    return 0.0


def robustness_points(scenario: str, claimed: Collection[str], standard: float) -> float:
    """Robustness points: total / applicable layers × claimed layers, when standard >= 50 % (FC26 §5.3.3)."""
    total = t.TOTAL_POINTS[scenario].get("robustness", 0.0)
    if not claimed or total <= 0:
        return 0.0
    layers = t.APPLICABLE_LAYERS[t.ROBUSTNESS_COLUMN[scenario]]
    unknown = sorted(set(claimed) - set(layers))
    if unknown:
        raise UserInputError(
            f"robustness_claims[{t.ROBUSTNESS_COLUMN[scenario]!r}]: {unknown} not applicable (expected from {layers})"
        )
    if round(standard, 6) < round(t.ROBUSTNESS_MIN_STANDARD_SHARE * t.TOTAL_POINTS[scenario]["standard"], 6):
        return 0.0
    return total / len(layers) * len(set(claimed))


def fc_points(
    scenario: str, standard: Sequence[str], extended: Sequence[str], claimed: Collection[str] = ()
) -> ScenarioPoints:
    """A Frontal Collisions scenario: standard mean sub-score × points (§5.3.1), extended share snapped (§5.3.2),
    robustness (§5.3.3)."""
    totals = t.TOTAL_POINTS[scenario]
    std = sum(t.STANDARD_SUB_SCORE[c] for c in standard) / len(standard) * totals["standard"] if standard else 0.0
    ext_raw = sum(t.EXTENDED_SUB_SCORE[c] for c in extended) / len(extended) * totals["extended"] if extended else 0.0
    ext = extended_step(ext_raw, totals["extended"])
    return ScenarioPoints(scenario, std, ext, robustness_points(scenario, claimed, std), len(standard), len(extended))


def lsc_points(scenario: str, colours: Sequence[str], corner_case: Sequence[bool]) -> ScenarioPoints:
    """A Low Speed Collisions scenario: mean colour weight over the grid's cells × points (R26
    `compute_lsc_loadcase_score`); corner-case cells count in the mean but weigh 0 (UNVERIFIED, tables)."""
    n = len(colours)
    weight = sum(t.STANDARD_SUB_SCORE[c] for c, corner in zip(colours, corner_case, strict=True) if not corner)
    std = weight / n * t.TOTAL_POINTS[scenario]["standard"] if n else 0.0
    return ScenarioPoints(scenario, std, 0.0, 0.0, n, 0)
