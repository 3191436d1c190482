"""The results folder of a sweep: what --force may replace and delete, and a hand-edited manifest."""

from __future__ import annotations

from pathlib import Path

import pyarrow as pa
import pytest
import yaml

from cli_helpers import assert_user_error, invoke
from conftest import PAPER_DIR
from vrusim.errors import UserInputError
from vrusim.sweep.store import SweepStore

SPEC = {
    "base": str(PAPER_DIR / "pedestrian_crossing.yaml"),
    "set": {"sim.duration_s": 2.0},
    "samples": 3,
    "parameters": {"ego.cruise_speed_mps": {"uniform": [8.0, 12.0]}},
}


def write_spec(folder: Path, **changes) -> Path:
    path = folder / "spec.yaml"
    path.write_text(yaml.safe_dump({**SPEC, **changes}))
    return path


def previous_sweep(folder: Path) -> SweepStore:
    """A folder holding a (tiny) previous sweep's files, as `SweepStore.create` and `write_chunk` leave them."""
    store = SweepStore(folder)
    store.create({"name": "old", "parameters": []}, pa.table({"variant": [0]}))
    store.write_chunk(0, pa.table({"variant": [0]}))
    return store


def test_force_refuses_a_folder_whose_manifest_is_not_a_sweeps(tmp_path):
    app = tmp_path / "myapp"
    (app / "chunks").mkdir(parents=True)
    (app / "manifest.json").write_text('{"name":"my-pwa"}')
    (app / "chunks" / "main.3f2a.js").write_text("js")
    result = invoke("sweep", write_spec(tmp_path), "--out", app, "--force")
    assert_user_error(result, "--out", "myapp", "holds no sweep results", "format")
    assert (app / "manifest.json").read_text() == '{"name":"my-pwa"}'
    assert (app / "chunks" / "main.3f2a.js").read_text() == "js"


def test_force_refuses_a_sweep_folder_whose_chunks_hold_other_files(tmp_path):
    store = previous_sweep(tmp_path / "out")
    (store.chunks / "main.3f2a.js").write_text("js")
    (store.chunks / "keep").mkdir()
    result = invoke("sweep", write_spec(tmp_path), "--out", store.folder, "--force")
    assert_user_error(result, "--out", "chunks", "did not write", "keep", "main.3f2a.js")
    assert store.manifest_path.is_file() and (store.chunks / "chunk-000000.parquet").is_file()


def test_replacing_a_sweep_deletes_only_its_own_files(tmp_path):
    store = previous_sweep(tmp_path / "out")
    (store.folder / "notes.txt").write_text("mine")
    (store.chunks / ".chunk-000001.parquet.x1.tmp").write_text("")
    store.check_new(replace=True)
    store.remove()
    assert sorted(p.name for p in store.folder.iterdir()) == ["notes.txt"]


def test_force_on_a_foreign_folder_with_a_folder_for_chunks_deletes_nothing(tmp_path):
    store = previous_sweep(tmp_path / "out")
    (store.chunks / "chunk-000004.parquet").mkdir()
    with pytest.raises(UserInputError, match=r"chunk-000004\.parquet"):
        store.check_new(replace=True)
    assert (store.chunks / "chunk-000004.parquet").is_dir()
