"""The results folder of a sweep: manifest, design, and one Parquet file per finished batch.

```
OUT/manifest.json                 spec, plan (bases, parameters, seed), digest, counts, code version
OUT/design.parquet                every variant's id, seed, test and parameter values
OUT/chunks/chunk-000000.parquet   results of batch 0 (design columns, then result columns), ...
```
Every file is written to a temporary name and renamed into place, so a batch file exists completely or
not at all: a sweep stopped at any instant (Ctrl-C, SIGKILL, a dead worker, a lost machine) leaves only
complete batches, and `--resume` runs exactly the missing ones. Each variant therefore appears exactly once.
"""

from __future__ import annotations

import contextlib
import json
import re
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from vrusim.errors import UserInputError
from vrusim.io.atomic import write_atomically
from vrusim.io.paths import check_output_folder, for_option, make_folder, remove_folders, shown
from vrusim.sweep.chunk_checks import foreign_message, non_finite_column, recorded_digest, with_plan_digest
from vrusim.sweep.manifest import FORMAT, MANIFEST, RESUME_KEYS, read_manifest

DESIGN = "design.parquet"
CHUNKS = "chunks"
_CHUNK_NAME = re.compile(r"chunk-(\d{6,})\.parquet")


def chunk_name(index: int) -> str:
    """File name of batch `index`."""
    return f"chunk-{index:06d}.parquet"


class SweepStore:
    """Reads and writes one sweep's results folder."""

    def __init__(self, folder: str | Path) -> None:
        self.folder = Path(folder)
        self.chunks = self.folder / CHUNKS
        self._created: list[Path] = []
        """The folders `create` made (removed again by `discard`)."""

    @property
    def manifest_path(self) -> Path:
        return self.folder / MANIFEST

    def check_new(self, replace: bool = False) -> None:
        """Refuse a folder that cannot take a new sweep: a file, or a folder that is not empty, unless `replace` and
        it holds a previous sweep's results (a vrusim-sweep/1 manifest, and in its chunks folder only files vrusim
        writes); or a path that cannot be a folder to write into (`vrusim.io.paths`)."""
        check_output_folder(self.folder, "--out")
        if not self.folder.exists() or (self.folder.is_dir() and not any(self.folder.iterdir())):
            return
        if not self.folder.is_dir() or not replace:
            raise UserInputError(
                f"--out: {shown(self.folder)} already exists and is not empty; use --resume to continue the sweep in "
                "it, --force to replace it, or choose a new folder"
            )
        try:
            read_manifest(self.folder)
        except UserInputError as error:
            raise UserInputError(
                f"--out: {shown(self.folder)} is not empty and holds no sweep results ({error}); --force replaces "
                "only a previous sweep, choose a new folder"
            ) from None
        foreign = self._foreign()
        if foreign:
            listed = ", ".join(shown(path.name) for path in foreign[:3]) + (", ..." if len(foreign) > 3 else "")
            raise UserInputError(
                f"--out: {shown(self.chunks)} holds files vrusim did not write ({listed}); --force deletes only a "
                "sweep's own files: move them away or choose a new folder"
            )

    def _foreign(self) -> list[Path]:
        """Entries of the chunks folder (or the path itself, if it is no folder) that are not vrusim's."""
        if not self.chunks.exists() and not self.chunks.is_symlink():
            return []
        if self.chunks.is_symlink() or not self.chunks.is_dir():
            return [self.chunks]
        return sorted(path for path in self.chunks.iterdir() if not _is_own(path))

    def remove(self) -> None:
        """Delete a previous sweep's files, only those vrusim writes: the manifest first (the folder stops being
        a sweep), the design, the batch files and temporary files, then the chunks folder if that left it empty."""
        self.manifest_path.unlink(missing_ok=True)
        (self.folder / DESIGN).unlink(missing_ok=True)
        if self.chunks.is_dir() and not self.chunks.is_symlink():
            for path in self.chunks.iterdir():
                if _is_own(path):
                    path.unlink()
            with contextlib.suppress(OSError):
                self.chunks.rmdir()

    def create(self, manifest: dict[str, Any], design: pa.Table, replace: bool = False) -> None:
        """Start a new results folder (missing or empty; with `replace`, one holding a previous sweep, whose files
        are deleted): design first, then the manifest that marks it."""
        self.check_new(replace)
        if replace:
            self.remove()
        self._created = make_folder(self.chunks, "--out")
        text = json.dumps({"format": FORMAT, **manifest}, indent=2, allow_nan=False, default=str)  # YAML dates
        try:
            with for_option("--out"):
                write_atomically(self.folder / DESIGN, lambda path: write_parquet(design, path), "sweep design")
                write_atomically(self.manifest_path, lambda path: path.write_text(text + "\n"), "sweep manifest")
        except BaseException:
            self.discard()
            raise

    def discard(self) -> None:
        """Undo `create` when the new sweep fails before its first batch is stored: delete its files and the
        folders it made (a folder that existed before stays, as does anything `create` did not write)."""
        try:
            self.remove()
        except OSError:  # pragma: no cover (a folder turned read-only meanwhile: leave what is there)
            return
        remove_folders(self._created)

    def manifest(self) -> dict[str, Any]:
        """The manifest of an existing results folder, with the plan `--resume` needs (`vrusim.sweep.manifest`)."""
        return read_manifest(self.folder, RESUME_KEYS)

    def design(self) -> pa.Table:
        """The stored design table."""
        try:
            return pq.read_table(self.folder / DESIGN)
        except (OSError, pa.ArrowException) as error:
            raise UserInputError(f"{self.folder / DESIGN}: cannot read the sweep design ({error})") from None

    def clean_temporary(self) -> int:
        """Remove temporary files left by an interrupted write; return how many."""
        removed = 0
        for path in self.chunks.glob(".*.tmp"):
            path.unlink(missing_ok=True)
            removed += 1
        return removed

    def batch_files(self) -> dict[int, Path]:
        """The batch files present (index → path; folders and links included, for `chunk_checks` to refuse); a
        name vrusim does not write for its index (`chunk-0000001.parquet`) is a UserInputError."""
        if not self.chunks.is_dir():
            return {}
        found = {}
        for path in self.chunks.iterdir():
            match = _CHUNK_NAME.fullmatch(path.name)
            if match:
                index = int(match.group(1))
                if path.name != chunk_name(index):
                    raise UserInputError(
                        f"{shown(path)}: not a name vrusim writes (batch {index} is {chunk_name(index)}); remove it"
                    )
                found[index] = path
        return found

    def finished(self) -> set[int]:
        """Indices of the batches whose results file exists."""
        return set(self.batch_files())

    def write_chunk(self, index: int, table: pa.Table, plan_digest: str | None = None) -> Path:
        """Write batch `index` atomically (recording `plan_digest`, `vrusim.sweep.chunk_checks`)."""
        if plan_digest is not None:
            table = with_plan_digest(table, plan_digest)
        with for_option("--out"):
            return write_atomically(self.chunks / chunk_name(index), lambda path: write_parquet(table, path), "results")

    def chunk_files(self) -> list[Path]:
        """The finished batch files, in batch order."""
        return [self.chunks / chunk_name(i) for i in sorted(self.finished())]

    def variant_ids(self) -> np.ndarray:
        """The `variant` column of every finished batch, concatenated in batch order."""
        parts = [_int64s(pq.ParquetFile(path).read(columns=["variant"]).column(0)) for path in self.chunk_files()]
        return np.concatenate(parts) if parts else np.zeros(0, dtype=np.int64)

    def _read_batch(self, path: Path, digest: str) -> pa.Table:
        """One batch file, refused (naming it) when unreadable, of another sweep, or holding NaN or infinity."""
        try:
            table = pq.read_table(path)
        except (OSError, pa.ArrowException) as error:
            raise UserInputError(f"{shown(path)}: cannot read this results file ({error})") from None
        recorded = recorded_digest(table.schema.metadata)
        if recorded is not None and recorded != digest:
            raise UserInputError(foreign_message(path, recorded, digest))
        column = non_finite_column(table)
        if column is not None:
            raise UserInputError(f"{shown(path)}: column {column} holds NaN or infinity, which vrusim never writes")
        return table

    def read(self) -> pa.Table:
        """Every finished row, sorted by variant (batches with other planners may add columns: NULL elsewhere)."""
        digest = self.manifest()["plan_sha256"]
        tables = [self._read_batch(path, digest) for path in self.chunk_files()]
        if not tables:
            raise UserInputError(f"{self.folder}: no finished batches yet")
        table = pa.concat_tables(tables, promote_options="default")
        return table.sort_by("variant")


def _is_own(path: Path) -> bool:
    """A file vrusim writes in the chunks folder: a batch file or a temporary file (not a folder or a link)."""
    own = _CHUNK_NAME.fullmatch(path.name) or (path.name.startswith(".") and path.name.endswith(".tmp"))
    return bool(own) and path.is_file() and not path.is_symlink()


def write_parquet(table: pa.Table, path: Path) -> None:
    """`table` as a Parquet file, dictionary-encoding only its text columns: numbers rarely repeat in a sweep,
    and without a dictionary a batch of 2,500 rows writes in about 5 instead of 7 ms and its file is smaller."""
    text = [f.name for f in table.schema if pa.types.is_string(f.type) or pa.types.is_large_string(f.type)]
    pq.write_table(table, path, use_dictionary=text)


def _int64s(column: pa.ChunkedArray) -> np.ndarray:
    """An int64 column without nulls as a NumPy array. Read from its buffer: `pq.read_table` and `to_numpy`
    import pandas (a fraction of a second of a sweep)."""
    array = column.combine_chunks()
    return np.frombuffer(array.buffers()[1], dtype=np.int64)[array.offset : array.offset + len(array)].copy()


def check_exactly_once(ids: np.ndarray, variants: int) -> tuple[int, int, int]:
    """(present, duplicated, missing) counts of variant ids 0 … variants−1."""
    counts = np.bincount(ids, minlength=variants) if ids.size else np.zeros(variants, dtype=np.int64)
    return int((counts > 0).sum()), int((counts > 1).sum()), int((counts[:variants] == 0).sum())
