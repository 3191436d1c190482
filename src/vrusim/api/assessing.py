"""`euro_ncap`: run the Euro NCAP AEB VRU catalogue (or part of it) in one batch and assess it as Euro NCAP would."""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import asdict, dataclass
from typing import TYPE_CHECKING, Any

from vrusim.api.settings import check_planner, renamed, v2x_switch
from vrusim.api.tables import arrow_table, html_table, pandas_frame
from vrusim.errors import UserInputError
from vrusim.ncap.assess import SCHEMA, Assessment, GroupScore, assess, result_rows
from vrusim.ncap.editions import edition
from vrusim.ncap.grid import CatalogueRun, run_tests, select
from vrusim.ncap.rated2026 import Rated2026, rate_2026

if TYPE_CHECKING:
    from pathlib import Path

    import pandas
    import pyarrow as pa

    from vrusim.ncap.rating2026 import Assessment2026
    from vrusim.ncap.verification import VerificationReport

GROUP_COLUMNS = ("group", "score", "max_points", "in_euro_ncap_total")
"""The columns a notebook shows of the group scores."""


@dataclass(frozen=True)
class NcapResults:
    """The outcome of `euro_ncap`: per-test rows, group scores and the Euro NCAP total."""

    planner: str
    v2x: bool
    night: bool
    rows: list[dict[str, Any]]
    """One row per test, as `vrusim ncap --out` writes results.csv: the simulation's values (SI units) joined
    with the assessment (criterion, colour, sub-score, speeds in km/h)."""
    assessment: Assessment
    catalogue_run: CatalogueRun

    @property
    def total(self) -> float:
        """The Euro NCAP points of the groups counted in its total (extensions excluded)."""
        return self.assessment.total

    @property
    def total_max(self) -> float:
        """The most points those groups can give."""
        return self.assessment.total_max

    @property
    def groups(self) -> tuple[GroupScore, ...]:
        """Every group's score: the Euro NCAP groups, then vrusim's extensions."""
        return self.assessment.groups

    def __len__(self) -> int:
        return len(self.rows)

    def __iter__(self) -> Iterator[dict[str, Any]]:
        return iter(self.rows)

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready dict, the document `vrusim ncap --json` prints."""
        return {
            "protocol": "2023",
            "planner": self.planner,
            "v2x": "on" if self.v2x else "off",
            "night": self.night,
            "assessment": self.assessment.to_dict(),
        }

    def to_arrow(self) -> pa.Table:
        """The per-test rows as a pyarrow Table."""
        return arrow_table(self.rows, {field.name: field.type for field in SCHEMA})

    def to_pandas(self) -> pandas.DataFrame:
        """The per-test rows as a pandas DataFrame (needs pandas, which vrusim does not install)."""
        return pandas_frame(self.to_arrow())

    def __repr__(self) -> str:
        return (
            f"NcapResults({len(self)} tests, planner {self.planner}, V2X {'on' if self.v2x else 'off'}: "
            f"Euro NCAP total {self.total:.2f} / {self.total_max:.2f} points)"
        )

    def _repr_html_(self) -> str:
        return html_table([asdict(group) for group in self.groups], GROUP_COLUMNS, repr(self))


@dataclass(frozen=True)
class NcapResults2026:
    """The outcome of `euro_ncap(protocol="2026")`: per-cell colours, scenario and sub-element points (before the
    laboratory's verification), and what follows from them: `verify()` and `write_predictions()`."""

    planner: str
    v2x: bool
    night: bool
    rated: Rated2026

    @property
    def assessment(self) -> Assessment2026:
        """Cells, scenario points and sub-element totals (FC26 §5, LSC26)."""
        return self.rated.assessment

    @property
    def rows(self) -> list[dict[str, Any]]:
        """One row per test, as `vrusim ncap --protocol 2026 --out` writes results.csv."""
        from vrusim.ncap.results2026 import result_rows_2026

        return result_rows_2026(self.rated.catalogue_run.rows, self.assessment)

    @property
    def sub_elements(self) -> dict[str, float]:
        """Points per sub-element (FC Pedestrian & Cyclist, LSC Pedestrian & Cyclist, the motorcyclist parts)."""
        return self.assessment.sub_elements

    @property
    def total(self) -> float:
        """The points of every sub-element assessed, summed."""
        return sum(self.sub_elements.values())

    def verify(self, draws: int = 1000, seed: int = 0, method: str = "VTA") -> VerificationReport:
        """Simulate `draws` laboratory verifications of these colours as predictions (FC26 §4)."""
        return self.rated.verify(draws, seed, method=method)

    def write_predictions(self, path: str | Path, method: str = "VTA") -> Path:
        """Fill Euro NCAP's prediction template (extra ncap2026) with the colours; `method` "VTA" or "Self claimed"."""
        return self.rated.write_predictions(path, method)

    def __len__(self) -> int:
        return len(self.rated.catalogue_run.rows)

    def __iter__(self) -> Iterator[dict[str, Any]]:
        return iter(self.rows)

    def to_arrow(self) -> pa.Table:
        """The per-test rows (run values joined with colour, criterion, KPI and grid place) as a pyarrow Table."""
        import pyarrow as pa

        return pa.Table.from_pylist(self.rows)

    def to_pandas(self) -> pandas.DataFrame:
        """The per-test rows as a pandas DataFrame (needs pandas, which vrusim does not install)."""
        return pandas_frame(self.to_arrow())

    def _repr_html_(self) -> str:
        points = [{"sub_element": name, "points": round(value, 3)} for name, value in self.sub_elements.items()]
        return html_table(points, ("sub_element", "points"), repr(self))

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready dict, the document `vrusim ncap --protocol 2026 --json` prints (without --verify)."""
        return {
            "protocol": "2026",
            "planner": self.planner,
            "v2x": "on" if self.v2x else "off",
            "assessment": self.assessment.to_dict(),
            "verification": None,
        }

    def __repr__(self) -> str:
        points = ", ".join(f"{name} {value:.2f}" for name, value in self.sub_elements.items())
        return (
            f"NcapResults2026({len(self)} tests, planner {self.planner}, V2X {'on' if self.v2x else 'off'}: {points})"
        )


def euro_ncap(
    scenarios: str | Sequence[str] | None = None,
    planner: str = "fsm",
    v2x: bool | str = False,
    night: bool = False,
    protocol: str | None = None,
) -> NcapResults | NcapResults2026:
    """Run Euro NCAP VRU catalogue tests as one batch and assess them (as `vrusim ncap`).

    `scenarios`: catalogue codes or prefixes (`"CPNA"`, `["CPTA", "CB"]`; `vrusim list` shows them); None:
    the whole catalogue. `planner`: a registered planner name. `v2x`: the roadside unit on ("on" / True) or
    off ("off" / False). `night`: also run the night tests. `protocol`: the edition, "2023" (NcapResults) or
    "2026" (NcapResults2026); None: the default edition. Bad input raises UserInputError naming the argument.
    """
    check_planner(planner)
    on = v2x_switch(v2x)
    codes = [scenarios] if isinstance(scenarios, str) else list(scenarios or [])
    if not isinstance(night, bool):
        raise UserInputError(f"night: expected True or False, got {night!r}")
    try:
        book = edition(protocol)
        tests = select(codes, night=night, protocol=book.name)
        if book.name == "2026":
            return NcapResults2026(planner, on, night, rate_2026(tests, planner=planner, v2x=on))
        catalogue_run = run_tests(tests, planner=planner, v2x=on)
    except UserInputError as error:
        raise renamed(error, {"--scenario:": "scenarios:", "--protocol:": "protocol:"}) from None
    assessment = assess(catalogue_run.rows)
    rows = result_rows(catalogue_run.rows, assessment)
    return NcapResults(planner, on, night, rows, assessment, catalogue_run)
