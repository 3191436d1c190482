"""The results folder of a sweep: what --force may replace and delete, and a hand-edited manifest."""

from __future__ import annotations

import json
import math
import shutil
from pathlib import Path

import pyarrow as pa
import pyarrow.parquet as pq
import pytest
import yaml

from cli_helpers import assert_user_error, invoke
from conftest import PAPER_DIR
from vrusim.cli.output import escape, report_user_error
from vrusim.cli.sweep import _saved
from vrusim.errors import UserInputError
from vrusim.sweep.chunk_checks import recorded_digest, with_plan_digest
from vrusim.sweep.runner import run_sweep
from vrusim.sweep.spec import load_spec
from vrusim.sweep.store import SweepStore, chunk_name

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


# --------------------------------------------------------------------------------------------- stored batches


@pytest.fixture(scope="module")
def finished(tmp_path_factory) -> Path:
    """A finished sweep of 4 variants in 4 batches (copied by each test before it is changed)."""
    folder = tmp_path_factory.mktemp("finished")
    spec = load_spec(write_spec(folder, samples=4, batch_size=1))
    run_sweep(spec, folder / "out", workers=1)
    return folder / "out"


@pytest.fixture
def sweep(finished, tmp_path) -> Path:
    return Path(shutil.copytree(finished, tmp_path / "sweep"))


def chunk(folder: Path, index: int) -> Path:
    return folder / "chunks" / chunk_name(index)


def rewrite(path: Path, change) -> None:
    """Rewrite a batch file with `change(table)` (keeping its metadata unless `change` replaces it)."""
    pq.write_table(change(pq.read_table(path)), path)


def test_resume_refuses_a_truncated_batch_file_naming_it(sweep):
    chunk(sweep, 1).write_bytes(chunk(sweep, 1).read_bytes()[:300])
    chunk(sweep, 2).unlink()
    assert_user_error(invoke("sweep", "--out", sweep, "--resume"), "chunk-000001.parquet", "cannot read")


def test_resume_refuses_a_stray_copy_beyond_the_last_batch(sweep):
    shutil.copy(chunk(sweep, 0), chunk(sweep, 9))
    assert_user_error(invoke("sweep", "--out", sweep, "--resume"), "chunk-000009.parquet", "no batch 9")


def test_resume_refuses_a_folder_named_like_a_batch_file(sweep):
    chunk(sweep, 3).unlink()
    chunk(sweep, 3).mkdir()
    assert_user_error(invoke("sweep", "--out", sweep, "--resume"), "chunk-000003.parquet", "folder")


def test_resume_refuses_a_batch_file_of_another_batch(sweep):
    shutil.copy(chunk(sweep, 0), chunk(sweep, 2))
    assert_user_error(invoke("sweep", "--out", sweep, "--resume"), "chunk-000002.parquet", "variants 2 … 2")


def test_resume_refuses_a_batch_file_of_another_sweep(sweep):
    rewrite(chunk(sweep, 1), lambda table: with_plan_digest(table, "0" * 64))
    chunk(sweep, 2).unlink()
    assert_user_error(invoke("sweep", "--out", sweep, "--resume"), "chunk-000001.parquet", "another sweep")
    assert_user_error(invoke("summarize", sweep), "chunk-000001.parquet", "another sweep")


def test_batch_files_record_their_plan_and_files_without_one_are_resumed(sweep):
    digest = json.loads((sweep / "manifest.json").read_text())["plan_sha256"]
    assert recorded_digest(pq.read_schema(chunk(sweep, 0)).metadata) == digest
    for index in range(3):  # as written before digests were recorded
        rewrite(chunk(sweep, index), lambda table: table.replace_schema_metadata(None))
    chunk(sweep, 3).unlink()
    result = invoke("sweep", "--out", sweep, "--resume", "--quiet")
    assert result.exit_code == 0, result.output
    assert SweepStore(sweep).read().column("variant").to_pylist() == [0, 1, 2, 3]


# --------------------------------------------------------------------------------------------- the manifest


def edit_manifest(folder: Path, change) -> None:
    path = folder / "manifest.json"
    manifest = json.loads(path.read_text())
    change(manifest)
    path.write_text(json.dumps(manifest))


@pytest.mark.parametrize(
    ("change", "command", "names"),
    [
        (lambda m: m.pop("plan"), ["sweep", "--resume", "--out"], ["manifest.json", "plan: missing"]),
        (lambda m: m.update(plan="x"), ["sweep", "--resume", "--out"], ["manifest.json", "plan: expected an object"]),
        (lambda m: m["plan"].pop("seed"), ["sweep", "--resume", "--out"], ["manifest.json", "plan.seed"]),
        (lambda m: m["plan"].update(parameters=[1]), ["sweep", "--resume", "--out"], ["manifest.json", "edited"]),
        (lambda m: m.update(code=5), ["report"], ["manifest.json", "code: expected an object"]),
        (lambda m: m.update(spec=[1], base_file=None), ["report"], ["manifest.json", "spec: expected an object"]),
        (lambda m: m.update(chunks=2), ["summarize"], ["chunks", "4 chunk files", "announces 2"]),
        (lambda m: m.update(chunks="2"), ["summarize"], ["manifest.json", "chunks: expected a whole number"]),
    ],
)
def test_a_hand_edited_manifest_is_one_message_naming_the_key(sweep, tmp_path, change, command, names):
    edit_manifest(sweep, change)
    extra = ["--out", tmp_path / "r.html"] if command == ["report"] else []
    assert_user_error(invoke(*command, sweep, *extra), *names)


# --------------------------------------------------------------------------------------------- NaN and infinity


def test_a_batch_file_holding_nan_or_infinity_is_refused_where_it_is_read(sweep, tmp_path):
    def poison(table: pa.Table) -> pa.Table:
        safety = table.column("safety").to_pylist()
        table = table.set_column(table.schema.get_field_index("safety"), "safety", pa.array([math.inf, *safety[1:]]))
        return table

    rewrite(chunk(sweep, 2), poison)
    for command in (["summarize", sweep, "--json"], ["report", sweep, "--out", tmp_path / "r.html"]):
        assert_user_error(invoke(*command), "chunk-000002.parquet", "safety", "NaN or infinity")
    with pytest.raises(UserInputError, match="safety"):
        SweepStore(sweep).read()


def test_a_parameter_column_holding_nan_is_refused_by_summarize(sweep):
    name = "ego.cruise_speed_mps"
    rewrite(chunk(sweep, 1), lambda t: t.set_column(t.schema.get_field_index(name), name, pa.array([math.nan])))
    assert_user_error(invoke("summarize", sweep, "--by", name), "chunk-000001.parquet", name)


# --------------------------------------------------------------------------------------------- user text on the console


@pytest.mark.parametrize("name", ["[/x]", "[bold red]EVIL[/]"])
def test_dry_run_prints_the_spec_name_literally(tmp_path, name):
    result = invoke("sweep", write_spec(tmp_path, name=name), "--dry-run")
    assert result.exit_code == 0, result.output
    assert name in result.stdout


def test_a_spec_name_with_a_terminal_escape_is_refused_without_echoing_it(tmp_path):
    result = invoke("sweep", write_spec(tmp_path, name="a\x1b[31mred"), "--dry-run")
    assert_user_error(result, "name", "control character U+001B")
    assert "\x1b" not in result.output


@pytest.mark.parametrize("folder", ["[x]", "[/x]"])
def test_the_summary_line_names_an_out_folder_with_brackets(finished, tmp_path, folder):
    result = invoke("sweep", write_spec(tmp_path, samples=1), "--out", tmp_path / folder, "--quiet")
    assert result.exit_code == 0, result.output
    assert f"{tmp_path / folder} in" in " ".join(result.stdout.split())


def test_user_errors_and_console_lines_show_control_characters_as_escapes(capsys):
    report_user_error(UserInputError("name a\x1b[2Jb\nsecond line\tok"))
    assert capsys.readouterr().err == "Error: name a\\x1b[2Jb\nsecond line\tok\n"
    assert escape("[/x]\x07") == "\\[/x]\\x07"


def test_an_interrupt_before_the_folder_exists_says_nothing_was_written(tmp_path):
    assert _saved(tmp_path / "m4") == "nothing was written"


# --------------------------------------------------------------------------------------------- options and spec keys


@pytest.mark.parametrize("size", ["1000001", "99999999999999999999", "0"])
def test_batch_size_option_has_the_spec_fields_range(tmp_path, size):
    assert_user_error(
        invoke("sweep", write_spec(tmp_path), "--dry-run", "--batch-size", size), "--batch-size", "1,000,000"
    )


def test_fifty_unknown_spec_keys_list_eight_and_count_the_rest(tmp_path):
    path = tmp_path / "s.yaml"
    path.write_text(yaml.safe_dump({**SPEC, **{f"key{i}": 1 for i in range(50)}}))
    result = invoke("sweep", path, "--dry-run")
    assert_user_error(result, "invalid sweep spec", "key0", "and 42 more")
    assert len(result.output.splitlines()) == 10


def test_more_workers_than_cores_are_capped_with_a_warning(monkeypatch, capsys):
    from vrusim.cli import sweep as sweep_cli

    monkeypatch.setattr("vrusim.sweep.execute.cpu_count", lambda: 2)
    assert sweep_cli._capped(8) == 2
    assert "Warning: --workers 8: this machine has 2 cores" in capsys.readouterr().err
    assert sweep_cli._capped(2) == 2 and capsys.readouterr().err == ""
