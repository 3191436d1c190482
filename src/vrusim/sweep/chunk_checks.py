"""Checks of a sweep's stored batch files, where they are read again (`--resume`, `summarize`, `report`, the API).

Each batch file records the digest of the plan it belongs to in its Parquet metadata (`PLAN_KEY`), so a file
copied in from another sweep (another seed, another spec) is refused instead of being taken as this sweep's
results. Files written before the digest was recorded have none: they are accepted as before, their variant ids
still checked against their batch. vrusim stores only finite numbers (an absent value is NULL), so a float
column holding NaN or infinity was not written by vrusim and is refused too. Every refusal is one
UserInputError naming the file (and the column).
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.parquet as pq

from vrusim.errors import UserInputError
from vrusim.io.paths import shown

PLAN_KEY = b"vrusim.plan_sha256"
"""Parquet (schema) metadata key of a batch file: the SHA-256 of its sweep's plan (`SweepPlan.digest`)."""
REDO = "delete it and --resume runs its batch again"


def with_plan_digest(table: pa.Table, digest: str) -> pa.Table:
    """`table` with its plan's digest in its schema metadata."""
    return table.replace_schema_metadata({**(table.schema.metadata or {}), PLAN_KEY: digest.encode()})


def recorded_digest(metadata: dict[bytes, bytes] | None) -> str | None:
    """The plan digest a batch file's schema metadata records (None: written before digests were recorded)."""
    value = (metadata or {}).get(PLAN_KEY)
    return None if value is None else value.decode("ascii", "replace")


def foreign_message(path: Path, recorded: str, digest: str) -> str:
    """The message for a batch file of another sweep."""
    return (
        f"{shown(path)}: this results file belongs to another sweep (its plan digest {recorded[:12]}… is not "
        f"{digest[:12]}… of this folder's manifest.json); remove it, or put it back where it came from"
    )


def check_batch_file(path: Path, start: int, stop: int, digest: str) -> None:
    """Refuse a batch file that cannot be read, belongs to another sweep, or does not hold exactly the variants
    start … stop − 1 of its batch (`--resume`)."""
    if not path.is_file() or path.is_symlink():
        raise UserInputError(f"{shown(path)}: not a results file vrusim wrote (a folder or a link); remove it")
    try:
        file = pq.ParquetFile(path)
        recorded = recorded_digest(file.schema_arrow.metadata)
        ids = file.read(columns=["variant"]).column(0).to_numpy(zero_copy_only=False)
    except (OSError, pa.ArrowException, KeyError, ValueError) as error:
        detail = str(error).strip().splitlines()[0] if str(error).strip() else type(error).__name__
        raise UserInputError(f"{shown(path)}: cannot read this results file ({detail}); {REDO}") from None
    if recorded is not None and recorded != digest:
        raise UserInputError(foreign_message(path, recorded, digest))
    if ids.dtype.kind not in "iu" or not np.array_equal(ids, np.arange(start, stop)):
        raise UserInputError(
            f"{shown(path)}: does not hold the variants {start} … {stop - 1} of its batch (another sweep's, or "
            f"edited?); {REDO}"
        )


def checked_batches(
    files: dict[int, Path], chunks: int, chunk_range: Callable[[int], tuple[int, int]], digest: str
) -> set[int]:
    """The batch indices of `files` (index → file), each file checked (`check_batch_file`); a file whose index
    is beyond the sweep's `chunks` batches is refused."""
    for index, path in sorted(files.items()):
        if index >= chunks:
            raise UserInputError(
                f"{shown(path)}: this sweep has batches 0 … {chunks - 1}, no batch {index} (a stray copy?); remove it"
            )
        check_batch_file(path, *chunk_range(index), digest)
    return set(files)


def non_finite_column(table: pa.Table) -> str | None:
    """The first float column of `table` holding NaN or infinity (None when every float is finite or NULL)."""
    for field in table.schema:
        if pa.types.is_floating(field.type):
            column = table.column(field.name)
            if column.null_count < len(column) and not pc.all(pc.is_finite(column)).as_py():
                return field.name
    return None
