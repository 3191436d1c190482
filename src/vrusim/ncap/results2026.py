"""2026 result rows and the verification file of a `vrusim ncap --protocol 2026 --out` folder.

`result_rows_2026` joins the run rows (`ncap.grid.run_tests`) with their assessed cells (`assess_2026`), so the
results.csv / results.parquet rows carry each test's colour, criterion, KPI, grid place and, when the lab
verification was simulated, the cell's pass probability. The points after verification (a distribution over
draws, not a per-test value) go to verification.json next to them (`VerificationReport.to_dict()`);
`read_verification(folder)` reads it back, None when the folder has none (then the report shows no verification).
"""

from __future__ import annotations

import json
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

from vrusim.errors import UserInputError
from vrusim.io.atomic import write_atomically
from vrusim.ncap.rating2026 import Assessment2026
from vrusim.ncap.rating2026 import tables as t
from vrusim.ncap.verification import Spread, VerificationReport

VERIFICATION_FILE = "verification.json"
"""The Monte Carlo verification of a 2026 results folder (absent when it was not run)."""
ADDED_COLUMNS = ("colour", "criterion", "kpi", "grid_row_label", "grid_column_label", "verification_pass_probability")
"""Columns `result_rows_2026` adds to every run row."""


def kpi_unit(criterion: str) -> str:
    """Unit of a cell's KPI: seconds for the warning TTC, else km/h (Vrel_impact / Vimpact)."""
    return "s" if criterion == t.WARNING else "km/h"


def result_rows_2026(
    run_rows: Iterable[Mapping[str, Any]],
    assessment: Assessment2026,
    verification: VerificationReport | None = None,
) -> list[dict[str, Any]]:
    """Each run row with its cell's `colour`, `criterion`, `kpi` (unit: `kpi_unit`), `grid_row_label`,
    `grid_column_label` and `verification_pass_probability` (None: not verified, or not a verification candidate:
    predicted red or a corner case). Rows are matched to cells by `test_id`."""
    cells = {c.test_id: c for c in assessment.cells}
    probabilities = verification.pass_probability if verification is not None else {}
    out = []
    for row in run_rows:
        test_id = str(row.get("test_id", ""))
        cell = cells.get(test_id)
        if cell is None:
            raise UserInputError(f"run_rows: test {test_id!r} is not in the assessment (assess these rows first)")
        out.append(
            {
                **row,
                "colour": cell.colour,
                "criterion": cell.criterion,
                "kpi": cell.kpi,
                "grid_row_label": cell.row_label,
                "grid_column_label": cell.column_label,
                "verification_pass_probability": probabilities.get(test_id),
            }
        )
    return out


def verification_from_dict(document: Mapping[str, Any]) -> VerificationReport:
    """A VerificationReport from its `to_dict()` (verification.json); a malformed one is a UserInputError."""
    try:
        return VerificationReport(
            n_draws=int(document["n_draws"]),
            n_perturbations=int(document["n_perturbations"]),
            seed=int(document["seed"]),
            method=str(document["method"]),
            pass_probability={str(k): float(v) for k, v in document["pass_probability"].items()},
            scenarios={str(k): Spread(**v) for k, v in document["scenarios"].items()},
            sub_elements={str(k): Spread(**v) for k, v in document["sub_elements"].items()},
            predicted={str(k): float(v) for k, v in document["predicted"].items()},
        )
    except (KeyError, TypeError, ValueError, AttributeError) as error:
        raise UserInputError(f"{VERIFICATION_FILE}: not a verification report ({error!r})") from None


def verification_text(verification: VerificationReport) -> str:
    """The verification.json document of a verification (read back by `read_verification`)."""
    return json.dumps(verification.to_dict(), indent=1, allow_nan=False)


def write_verification(verification: VerificationReport, folder: str | Path) -> Path:
    """Write FOLDER/verification.json atomically; return its path."""
    text = verification_text(verification)
    path = Path(folder) / VERIFICATION_FILE
    return write_atomically(path, lambda temp: temp.write_text(text, encoding="utf-8"), "verification")


def read_verification(folder: str | Path) -> VerificationReport | None:
    """FOLDER/verification.json as a VerificationReport, None when there is none."""
    path = Path(folder) / VERIFICATION_FILE
    if not path.is_file():
        return None
    try:
        document = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError) as error:
        raise UserInputError(f"SOURCE: cannot read {path} ({error})") from None
    return verification_from_dict(document)
