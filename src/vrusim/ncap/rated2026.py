"""A 2026 catalogue run with its assessment, and what follows from it: the predictions file for Euro NCAP's
calculator and the simulated laboratory verification (FC26 §4)."""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

from vrusim.ncap.build import NcapTest
from vrusim.ncap.grid import CatalogueRun, run_tests
from vrusim.ncap.rating2026 import Assessment2026, assess_2026
from vrusim.ncap.verification import VerificationReport, monte_carlo, vrusim_simulator

VERIFY_PERTURBATIONS = 16
"""Tolerance runs simulated per eligible cell; the lab's draws resample them (ncap/verification.py)."""


@dataclass(frozen=True)
class Rated2026:
    """The tests of a 2026 selection run in one batch, and their assessment (points before verification)."""

    catalogue_run: CatalogueRun
    assessment: Assessment2026
    planner: str
    v2x: bool

    def verify(
        self, draws: int = 1000, seed: int = 0, perturbations: int = VERIFY_PERTURBATIONS, method: str = "VTA"
    ) -> VerificationReport:
        """`draws` simulated laboratory verifications of the assessment's colours as predictions: per-cell pass
        probabilities and the points after verification (mean, spread). All tolerance runs are one batch."""
        scenarios = {built.test.test_id: built.scenario for built in self.catalogue_run.built}
        simulator = vrusim_simulator(scenarios, self.planner)
        return monte_carlo(self.assessment, simulator, draws, perturbations, seed, method)

    def write_predictions(self, path: str | Path, method: str = "VTA") -> Path:
        """Fill Euro NCAP's own prediction template with the simulated colours (needs the ncap2026 extra)."""
        from vrusim.ncap.predictions import write_predictions

        return write_predictions(self.assessment, path, method)


def rate_2026(tests: Iterable[NcapTest], planner: str = "fsm", v2x: bool = False) -> Rated2026:
    """Run 2026 tests as one batch and assess them (FC26 §5, LSC26)."""
    catalogue_run = run_tests(tests, planner=planner, v2x=v2x)
    return Rated2026(catalogue_run, assess_2026(catalogue_run.rows), planner, v2x)
