"""`load` and `run`: scenarios in, a `Results` object out (summary rows, Arrow / pandas tables, traces)."""

from __future__ import annotations

from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from vrusim.api.settings import check_planner
from vrusim.api.tables import SUMMARY_TYPES, arrow_table, html_table, pandas_frame
from vrusim.engine.simulate import BatchRun, simulate
from vrusim.errors import UserInputError
from vrusim.metrics.outcome import outcome_counts, outcome_of
from vrusim.metrics.summary import summary_rows
from vrusim.scenario.schema import Scenario
from vrusim.scenario.settings import V2XSetting, with_settings
from vrusim.sources import ScenarioSource, scenario_of

if TYPE_CHECKING:
    import pandas
    import pyarrow as pa

    from vrusim.viz.recording import Recording

KEY_COLUMNS = (
    "scenario",
    "planner",
    "v2x",
    "outcome",
    "contact_time_s",
    "impact_ego_speed_mps",
    "min_ttc_s",
    "min_clearance_m",
    "safety",
    "efficiency",
    "comfort",
)
"""The columns a notebook shows of a Results object (all of them are in `rows` and the tables)."""


def load(source: ScenarioSource) -> Scenario:
    """The Scenario a source names, validated.

    `source`: a YAML file path (str or Path); a bundled scenario (`paper:pedestrian`, `paper:escooter`,
    `paper:motorcyclist`, `example:right-turn-cyclist`); or one Euro NCAP catalogue test id such as
    `CPNCO-50/30kph/day` (built for the `fsm` planner with V2X off, its roadside unit placed, so
    `run(..., v2x="on")` works). A Scenario is returned as it is. Bad input raises UserInputError.
    """
    return scenario_of(source, argument="source")


@dataclass(frozen=True)
class _Where:
    """Which batch run, and which variant of it, produced a row."""

    run: BatchRun
    variant: int


@dataclass(frozen=True)
class Results:
    """The outcome of `run`: one summary row per scenario, in the order given.

    `rows` are the dicts `vrusim run --json` prints (SI units, field names carry the unit; absent values
    None): outcome, impact, event times, metrics and safety / efficiency / comfort scores.
    """

    scenarios: tuple[Scenario, ...]
    """The scenarios as run (planner, V2X setting and seed applied)."""
    rows: list[dict[str, Any]]
    _where: tuple[_Where, ...] = field(repr=False)

    def __len__(self) -> int:
        return len(self.rows)

    def __iter__(self) -> Iterator[dict[str, Any]]:
        return iter(self.rows)

    def __getitem__(self, index: int) -> dict[str, Any]:
        return self.rows[index]

    def to_arrow(self) -> pa.Table:
        """The rows as a pyarrow Table, one column per row key (`first_mode_s` a struct, `transitions` a list)."""
        return arrow_table(self.rows, SUMMARY_TYPES)

    def to_pandas(self) -> pandas.DataFrame:
        """The rows as a pandas DataFrame (needs pandas, which vrusim does not install)."""
        return pandas_frame(self.to_arrow())

    @property
    def trace(self) -> pa.Table:
        """The per-step trace of a single-scenario run, as `vrusim run --trace` writes it (one row per step:
        t_s, the ego state and command, the planner mode, clearance, TTC, then per VRU position, speed,
        detection). For several scenarios use `trace_of(index)`."""
        if len(self) != 1:
            raise ValueError(f"these results hold {len(self)} runs; take one trace with trace_of(index)")
        return self.trace_of(0)

    def trace_of(self, index: int) -> pa.Table:
        """The per-step trace of the run at `index` (recorded when `run(..., trace=True)`; always for one
        Scenario)."""
        from vrusim.engine.trace_file import trace_table

        where = self._where[index]
        if where.run.trace is None:
            raise ValueError("no trace was recorded: run(..., trace=True)")
        return trace_table(where.run, where.variant)

    def __repr__(self) -> str:
        planners = ", ".join(dict.fromkeys(row["planner"] for row in self.rows))
        if len(self) == 1:
            row = self.rows[0]
            outcome = f"collision at {row['contact_time_s']:.2f} s" if row["collided"] else outcome_of(row)
            scores = ", ".join(f"{name} {row[name]:.2f}" for name in ("safety", "efficiency", "comfort"))
            v2x = "on" if row["v2x"] else "off"
            return f"Results({row['scenario']}: {outcome}; planner {planners}, V2X {v2x}; {scores})"
        return f"Results({len(self)} runs: {outcome_counts(self.rows)}; planner {planners})"

    def _repr_html_(self) -> str:
        """The key columns as a table; a single traced run adds its scene player (`vrusim.report.player`)."""
        text = html_table(self.rows, KEY_COLUMNS, repr(self))
        recording = self._recording()
        if recording is None:
            return text
        from vrusim.report.player import embedded_player

        return text + embedded_player([recording])

    def _recording(self) -> Recording | None:
        """The Recording of a single run with a trace (None otherwise)."""
        if len(self) != 1 or self._where[0].run.trace is None or self._where[0].run.params.size != 1:
            return None
        from vrusim.viz.recording import recordings_of

        return recordings_of(self._where[0].run, [self.scenarios[0]])[0]


def _sources(scenarios: ScenarioSource | Iterable[ScenarioSource]) -> tuple[list[ScenarioSource], bool]:
    """The scenario sources and whether a single one was given (not in a list)."""
    if isinstance(scenarios, Scenario | str | Path):
        return [scenarios], True
    if not isinstance(scenarios, Iterable):
        raise UserInputError(f"scenarios: expected a Scenario, a source or a list of them, got {scenarios!r}")
    sources = list(scenarios)
    if not sources:
        raise UserInputError("scenarios: the list is empty; give at least one scenario")
    return sources, False


def run(
    scenarios: ScenarioSource | Sequence[ScenarioSource],
    planner: str | None = None,
    v2x: V2XSetting | None = None,
    seed: int | None = None,
    trace: bool | None = None,
) -> Results:
    """Simulate one scenario or many and summarise each run.

    `scenarios`: a Scenario, or anything `load` takes, or a list of them. `planner`: a registered planner name
    (`fsm`, `none`, `aeb`, `predictive`, `module:Class` or an entry point); None keeps each scenario's.
    `v2x`: "on" / True, "off" / False, a channel profile name ("ideal", "typical", ...) or a channel
    specification; None keeps each scenario's. `seed`: sets `sim.seed` (the key of the sensor's and the
    channel's random numbers); None keeps it. `trace`: record per-step traces (None: only for a single
    Scenario, not given in a list). Scenarios with the same planner run as one batch; a variant's result does
    not depend on its batch. Bad input raises UserInputError naming the argument.
    """
    sources, single = _sources(scenarios)
    if planner is not None:
        check_planner(planner)
    prepared = [
        with_settings(
            scenario_of(source, argument="scenarios" if single else f"scenarios[{index}]"), planner, v2x, seed
        )
        for index, source in enumerate(sources)
    ]
    record = single if trace is None else bool(trace)
    by_planner: dict[str, list[int]] = {}
    for index, scenario in enumerate(prepared):
        by_planner.setdefault(scenario.planner.name, []).append(index)
    rows: list[dict[str, Any]] = [{} for _ in prepared]
    where: list[_Where | None] = [None] * len(prepared)
    for members in by_planner.values():
        batch = simulate([prepared[i] for i in members], trace=record)
        for variant, (index, row) in enumerate(zip(members, summary_rows(batch), strict=True)):
            rows[index] = row
            where[index] = _Where(batch, variant)
    return Results(tuple(prepared), rows, tuple(w for w in where if w is not None))
