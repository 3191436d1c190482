"""`vrusim ncap --protocol 2026`: run the 2026 grid, assess it (FC26 §5, LSC26), and on request write the
predictions file for Euro NCAP's calculator and simulate the laboratory's verification."""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import typer
from rich.markup import escape

from vrusim.cli.output import console, print_json
from vrusim.errors import UserInputError

if TYPE_CHECKING:
    from vrusim.ncap.build import NcapTest
    from vrusim.ncap.rated2026 import Rated2026
    from vrusim.ncap.verification import VerificationReport

OUTPUT_FILES = ("results.csv", "results.parquet", "scorecard.png", "verification.json")
"""What `vrusim ncap --out DIR` may write (both editions; verification.json: 2026 with --verify)."""
PREDICTION_SUFFIXES = (".xlsx",)


@dataclass(frozen=True)
class Options2026:
    """The 2026-only options, checked before anything runs."""

    predictions: Path | None
    verify_draws: int
    seed: int


def check_2026_options(
    protocol: str, predictions: Path | None, verify: int, seed: int | None, out: Path | None = None
) -> Options2026:
    """Refuse, before any work: 2026-only options with another edition, a bad draw count, a predictions path
    that cannot be written (its folder may be inside the --out folder `out`, created when it is written), or a
    missing calculator extra."""
    if protocol != "2026":
        for option, given in (("--predictions", predictions is not None), ("--verify", verify != 0)):
            if given:
                raise UserInputError(f"{option}: only with --protocol 2026 (the edition is {protocol})")
    if not 0 <= verify <= 100_000:
        raise UserInputError(f"--verify: expected a number of draws from 0 to 100000, got {verify}")
    if predictions is not None:
        from vrusim.extras import extra

        _check_predictions_file(predictions, out)
        with extra("ncap2026"):
            import euroncap_rating_2026  # noqa: F401
    return Options2026(predictions, verify, seed or 0)


def _check_predictions_file(predictions: Path, out: Path | None) -> None:
    """`--predictions` can be written: in an existing folder, or in a missing one inside the --out folder (which
    `vrusim ncap` creates; it is checked by --out)."""
    from vrusim.io.paths import check_name, check_output_file, check_output_folder, shown

    if predictions.suffix.lower() not in PREDICTION_SUFFIXES:
        found = predictions.suffix or "(no suffix)"
        raise UserInputError(
            f"--predictions: {shown(predictions)}: unknown predictions file type {found!r}; use "
            f"{', '.join(PREDICTION_SUFFIXES)}"
        )
    folder = check_name(predictions, "--predictions").parent
    inside_out = out is not None and folder.resolve().is_relative_to(out.resolve())
    if inside_out and not folder.exists():
        check_output_folder(folder, "--predictions")
        return
    check_output_file(predictions, "--predictions")


def run_2026(tests: list[NcapTest], planner: str, v2x: bool) -> tuple[Rated2026, float]:
    """Run and assess the tests (one batch); (the rating, wall seconds of the run)."""
    from vrusim.ncap.rated2026 import rate_2026

    started = time.perf_counter()
    rated = rate_2026(tests, planner=planner, v2x=v2x)
    return rated, time.perf_counter() - started


def write_2026_outputs(
    rated: Rated2026, verification: VerificationReport | None, folder: Path | None, predictions: Path | None
) -> list[Path]:
    """results.csv / .parquet, scorecard.png (and verification.json) in `folder`, all or none; the predictions
    file. Returns what was written."""
    from vrusim.io.paths import for_option, new_folder

    written: list[Path] = []
    if predictions is not None:  # first: it can refuse an assessment, the folder's files cannot
        # its folder, when missing, is inside --out (`check_2026_options`): created, and removed again if refused
        with new_folder(predictions.parent, "--predictions"), for_option("--predictions"):
            written.append(rated.write_predictions(predictions))
        from vrusim.ncap.predictions import unpredicted_scenarios

        blank = unpredicted_scenarios(rated.assessment)
        if blank:
            typer.echo(
                f"Note: {predictions} leaves {len(blank)} of the calculator's VRU scenarios blank "
                f"({', '.join(blank)}). The calculator scores blank grids too (a blank Frontal Collisions grid can "
                "earn its robustness points): only the whole grid (--night, no --scenario) gives vrusim's points.",
                err=True,
            )
    if folder is not None:
        written += _write_folder(rated, verification, folder)
    return written


def _write_folder(rated: Rated2026, verification: VerificationReport | None, folder: Path) -> list[Path]:
    import pyarrow as pa
    import pyarrow.csv as pa_csv
    import pyarrow.parquet as pq

    from vrusim.io.atomic import write_together
    from vrusim.io.paths import for_option, new_folder
    from vrusim.ncap.results2026 import result_rows_2026, verification_text
    from vrusim.viz.scorecard2026 import scorecard_2026_figure

    table = pa.Table.from_pylist(result_rows_2026(rated.catalogue_run.rows, rated.assessment, verification))
    figure = scorecard_2026_figure(rated.assessment, verification=verification)
    csv_name, parquet_name, png_name, json_name = OUTPUT_FILES
    targets = [
        (folder / csv_name, lambda temp: pa_csv.write_csv(table, temp), "results"),
        (folder / parquet_name, lambda temp: pq.write_table(table, temp), "results"),
        (folder / png_name, lambda temp: figure.savefig(temp, format="png"), "scorecard"),
    ]
    if verification is not None:
        text = verification_text(verification)
        targets.append((folder / json_name, lambda temp: temp.write_text(text, encoding="utf-8"), "verification"))
    with new_folder(folder, "--out"), for_option("--out"):
        written = write_together(targets)
    if verification is None:  # a verification of an earlier run (--force) would not describe these results
        (folder / json_name).unlink(missing_ok=True)
    return written


def print_2026(
    rated: Rated2026, verification: VerificationReport | None, elapsed_s: float, written: list[Path], as_json: bool
) -> None:
    """The scorecard on the terminal, or one JSON document."""
    if as_json:
        print_json(
            {
                "protocol": "2026",
                "planner": rated.planner,
                "v2x": "on" if rated.v2x else "off",
                "assessment": rated.assessment.to_dict(),
                "verification": None if verification is None else verification.to_dict(),
            }
        )
        return
    from vrusim.viz.scorecard2026_terminal import scorecard_2026_renderables

    terminal = console()
    for renderable in scorecard_2026_renderables(rated.assessment, verification):
        terminal.print(renderable)
    run = rated.catalogue_run.run
    terminal.print(
        f"{len(rated.catalogue_run.rows)} tests (protocol 2026), planner {rated.planner}, "
        f"V2X {'on' if rated.v2x else 'off'}: simulated in one batch in {elapsed_s:.2f} s ({run.steps} steps)."
    )
    for path in written:
        terminal.print(f"Wrote {escape(str(path))}")
