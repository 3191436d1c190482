"""`run_sweep` and `open_sweep`: run a sweep spec into a results folder, and read a results folder back."""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from vrusim.api.settings import renamed
from vrusim.api.tables import pandas_frame
from vrusim.errors import UserInputError
from vrusim.sources import is_bundled_name, scenario_file, sweep_spec_path
from vrusim.sweep.runner import SweepResult
from vrusim.sweep.spec import SweepSpec, load_spec, spec_from_mapping
from vrusim.sweep.store import SweepStore

if TYPE_CHECKING:
    import pandas
    import pyarrow as pa

CLI_NAMES = {
    "SPEC:": "spec:",
    "--out:": "out:",
    "--resume": "resume=True",
    "--workers:": "workers:",
    "--batch-size:": "batch_size:",
    "--scheduler:": "scheduler:",
    "--by:": "by:",
    "--bins:": "bins:",
    "--metrics:": "metrics:",
}
"""The sweep's command-line option names in its messages, and the API's argument names for them."""


@dataclass(frozen=True)
class SweepFolder:
    """A sweep's results folder (manifest, design, one Parquet file per finished batch), read on demand."""

    folder: Path
    outcome: SweepResult | None = None
    """What `run_sweep` did (batches run and reused, timing, warnings); None for `open_sweep`."""

    @property
    def manifest(self) -> dict[str, Any]:
        """The manifest: spec, plan, counts and the code version that ran the sweep."""
        return SweepStore(self.folder).manifest()

    @property
    def variants(self) -> int:
        """How many variants the sweep has (finished or not)."""
        return int(self.manifest["variants"])

    def to_arrow(self) -> pa.Table:
        """Every finished variant as a pyarrow Table, sorted by `variant`: design columns (id, seed, each swept
        parameter by its dotted path, `test` for a catalogue sweep), then the result columns."""
        try:
            return SweepStore(self.folder).read()
        except UserInputError as error:
            raise renamed(error, CLI_NAMES) from None

    def to_pandas(self) -> pandas.DataFrame:
        """The finished variants as a pandas DataFrame (needs pandas, which vrusim does not install)."""
        return pandas_frame(self.to_arrow())

    def summarize(self, by: str | Iterable[str] = (), bins: int = 10, metrics: Iterable[str] | None = None) -> dict:
        """Collision probability (Wilson 95 % interval) and metric statistics, overall and per group of the
        parameters in `by` (as `vrusim summarize --json`)."""
        from vrusim.sweep.summarize import summarize

        try:
            return summarize(self.folder, by, bins, metrics)
        except UserInputError as error:
            raise renamed(error, CLI_NAMES) from None

    def __len__(self) -> int:
        """How many variants are finished."""
        return int(SweepStore(self.folder).variant_ids().size)

    def __repr__(self) -> str:
        return f"SweepFolder({str(self.folder)!r}: {len(self):,} of {self.variants:,} variants finished)"


def _spec(spec: SweepSpec | str | Path | Mapping[str, Any]) -> SweepSpec:
    if isinstance(spec, SweepSpec):
        return spec
    if isinstance(spec, Mapping):
        data = dict(spec)
        base = data.get("base")
        if isinstance(base, str) and is_bundled_name(base):
            data["base"] = str(scenario_file(base, "spec: base"))
        return spec_from_mapping(data, "spec", Path.cwd())
    if isinstance(spec, str | Path):
        return load_spec(sweep_spec_path(spec, "spec"))
    raise UserInputError(f"spec: expected a sweep spec file, a bundled spec name or a mapping, got {spec!r}")


def run_sweep(
    spec: SweepSpec | str | Path | Mapping[str, Any] | None,
    out: str | Path,
    workers: int = 1,
    batch_size: int | None = None,
    resume: bool = False,
    scheduler: str | None = None,
) -> SweepFolder:
    """Run every variant of a sweep spec into the results folder `out` (as `vrusim sweep`); return it.

    `spec`: a sweep spec YAML file, a bundled spec (`example:pedestrian-monte-carlo`), or the document as a
    mapping (relative paths resolve against the current folder; `base` may be a bundled scenario name); None
    with `resume`. `out`: a new or empty folder, or the one to resume. `workers`: local processes (1: in this
    process). `batch_size`: variants per batch (default: the spec's). `resume`: run the batches still missing
    in `out`. `scheduler`: a Dask scheduler address (`tcp://host:port`) to run on instead. Bad input raises
    UserInputError naming the argument.
    """
    from vrusim.sweep.runner import run_sweep as run_spec

    try:
        loaded = None if spec is None else _spec(spec)
        outcome = run_spec(loaded, out, workers, scheduler, batch_size, resume)
    except UserInputError as error:
        raise renamed(error, CLI_NAMES) from None
    return SweepFolder(Path(out), outcome)


def open_sweep(folder: str | Path) -> SweepFolder:
    """A sweep's results folder (from `run_sweep` or `vrusim sweep`), to read as tables or summarize."""
    store = SweepStore(folder)
    try:
        store.manifest()
    except UserInputError as error:
        raise renamed(error, CLI_NAMES) from None
    return SweepFolder(Path(folder))
