"""Output paths (issue 18, docs/errors.md): every way the file system can refuse an output option — a name too
long or with a null byte, a path under a regular file, a read-only folder, a special file in the way, a full
disk — is one message naming the option (exit 2, no traceback), and nothing is left on disk. Sweeps check
--scheduler before writing and leave nothing behind when they fail before their first batch."""

from __future__ import annotations

import errno
import json
import os
from pathlib import Path

import pytest
import yaml

import vrusim.io.atomic
import vrusim.sweep.execute
from cli_helpers import assert_user_error, invoke
from conftest import PAPER_DIR
from vrusim.errors import UserInputError
from vrusim.io.paths import SHOWN_CHARS, check_output_file, check_output_folder, shown

SPEC = {
    "base": str(PAPER_DIR / "pedestrian_crossing.yaml"),
    "set": {"sim.duration_s": 4.0},
    "parameters": {"ego.cruise_speed_mps": [10.0, 12.0, 14.0, 16.0]},
    "samples": 1,
    "batch_size": 1,
}
NCAP = ("ncap", "--protocol", "2023", "--scenario", "CPNA-25")

FILE_OPTIONS = {
    "run --trace": (lambda p, t: ("run", "paper:pedestrian", "--trace", p), "--trace", ".csv"),
    "run --plot": (lambda p, t: ("run", "paper:pedestrian", "--plot", p), "--plot", ".png"),
    "run --animate": (lambda p, t: ("run", "paper:pedestrian", "--animate", p), "--animate", ".gif"),
    "report OUT": (lambda p, t: ("report", "paper:pedestrian", "--out", p), "--out", ".html"),
    "ncap --report": (lambda p, t: (*NCAP, "--report", p), "--report", ".html"),
    "ncap --predictions": (
        lambda p, t: ("ncap", "--protocol", "2026", "--scenario", "CPNA", "--predictions", p),
        "--predictions",
        ".xlsx",
    ),
    "paper --report": (lambda p, t: ("paper", "--report", p), "--report", ".html"),
    "summarize --plot": (
        lambda p, t: ("summarize", t, "--plot", p, "--x", "ego.cruise_speed_mps"),
        "--plot",
        ".png",
    ),
}
FOLDER_OPTIONS = {
    "sweep --out": (lambda p, t: ("sweep", t / "spec.yaml", "--out", p, "--workers", "1", "--quiet"), "--out"),
    "ncap --out": (lambda p, t: (*NCAP, "--out", p), "--out"),
    "export --out": (lambda p, t: ("export", "paper:pedestrian", "--format", "openscenario", "--out", p), "--out"),
    "paper --figures": (lambda p, t: ("paper", "--figures", p), "--figures"),
}


@pytest.fixture(scope="module")
def sweep_results(tmp_path_factory) -> Path:
    """A finished four-variant sweep (for `summarize --plot`)."""
    folder = tmp_path_factory.mktemp("results")
    spec = _spec(folder)
    assert invoke("sweep", spec, "--out", folder / "out", "--workers", "1", "--quiet").exit_code == 0
    return folder / "out"


def _spec(folder: Path) -> Path:
    path = folder / "spec.yaml"
    path.write_text(yaml.safe_dump(SPEC))
    return path


def _files(folder: Path) -> set[Path]:
    return set(folder.rglob("*"))


@pytest.fixture
def read_only_folder(tmp_path) -> Path:
    """A folder this process cannot write into: chmod 555 for a normal user; as root (who writes through file
    modes) /proc/self, which refuses new files to everyone."""
    if os.geteuid() != 0:
        folder = tmp_path / "read-only"
        folder.mkdir()
        folder.chmod(0o555)
        yield folder
        folder.chmod(0o755)
        return
    proc = Path("/proc/self")
    if not proc.is_dir() or os.access(proc, os.W_OK):
        pytest.skip("running as root and /proc/self is not a read-only folder here")
    yield proc


def _bad_paths(tmp_path: Path, suffix: str) -> dict[str, tuple[str, list[str]]]:
    """Failure class → (path, words the message must hold)."""
    (tmp_path / "a-file").write_text("")
    return {
        "name too long": (str(tmp_path / ("x" * 300 + suffix)), ["File name too long"]),
        "path too long": (str(tmp_path / "/".join(["y" * 200] * 25)) + suffix, ["File name too long"]),
        "null byte": (f"{tmp_path}/a\0b{suffix}", ["null byte"]),
        "under a file": (str(tmp_path / "a-file" / f"x{suffix}"), ["a-file", "not a folder" if not suffix else "file"]),
    }


def _check_refused(result, option: str, words: list[str]) -> None:
    assert_user_error(result, option, *words)
    if not result.output.startswith("Usage:"):  # typer refuses a null byte in a Path option itself, also exit 2
        assert len(result.output.splitlines()) == 1 and len(result.output) < 400, result.output


@pytest.mark.parametrize("case", FILE_OPTIONS)
def test_file_options_refuse_unusable_paths_up_front(tmp_path, case):
    args, option, suffix = FILE_OPTIONS[case]
    _spec(tmp_path)
    for name, (path, words) in _bad_paths(tmp_path, suffix).items():
        before = _files(tmp_path)
        _check_refused(invoke(*args(path, tmp_path / "results")), option, words)
        assert _files(tmp_path) == before, name


@pytest.mark.parametrize("case", FOLDER_OPTIONS)
def test_folder_options_refuse_unusable_paths_up_front(tmp_path, case):
    args, option = FOLDER_OPTIONS[case]
    _spec(tmp_path)
    for name, (path, words) in _bad_paths(tmp_path, "").items():
        before = _files(tmp_path)
        _check_refused(invoke(*args(path, tmp_path)), option, words)
        assert _files(tmp_path) == before, name
    _check_refused(invoke(*args(tmp_path / "a-file", tmp_path)), option, ["exists and is not a folder"])
    _check_refused(invoke(*args(tmp_path / "a-file" / "deeper" / "out", tmp_path)), option, ["not a folder"])


@pytest.mark.parametrize("case", [*FILE_OPTIONS, *FOLDER_OPTIONS])
def test_a_read_only_folder_is_refused_up_front(tmp_path, read_only_folder, case):
    if case in FILE_OPTIONS:
        args, option, suffix = FILE_OPTIONS[case]
    else:
        (args, option), suffix = FOLDER_OPTIONS[case], ""
    _spec(tmp_path)
    before = set(os.listdir(read_only_folder))
    where = tmp_path / "results" if case in FILE_OPTIONS else tmp_path
    _check_refused(invoke(*args(read_only_folder / f"new{suffix}", where)), option, ["not writable"])
    assert set(os.listdir(read_only_folder)) == before


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs FIFOs")
@pytest.mark.parametrize("case", ["run --trace", "report OUT", "ncap --report"])
def test_a_special_file_in_the_way_is_not_replaced(tmp_path, case):
    args, option, suffix = FILE_OPTIONS[case]
    fifo = tmp_path / f"fifo{suffix}"
    os.mkfifo(fifo)
    _check_refused(invoke(*args(fifo, tmp_path)), option, ["not a regular file"])
    assert fifo.is_fifo()


def _disk_full(monkeypatch) -> list[Path]:
    """Make every file write fail with ENOSPC after half a file; returns the temporary files it saw."""
    seen: list[Path] = []

    def full(write, temp: Path) -> None:
        seen.append(temp)
        temp.write_bytes(b"half")
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(vrusim.io.atomic, "run_writer", full)
    return seen


@pytest.mark.parametrize("case", [*FILE_OPTIONS, *FOLDER_OPTIONS])
def test_a_full_disk_while_writing_leaves_nothing(tmp_path, sweep_results, monkeypatch, case):
    if case in FILE_OPTIONS:
        args, option, suffix = FILE_OPTIONS[case]
    else:
        (args, option), suffix = FOLDER_OPTIONS[case], ""
    work = tmp_path / "work"
    work.mkdir()
    _spec(work)
    before = _files(work)
    seen = _disk_full(monkeypatch)
    nested = not suffix and case != "paper --figures"  # --figures creates one level only
    target = work / "new" / "out" if nested else work / f"out{suffix}"
    _check_refused(
        invoke(*args(target, sweep_results if case == "summarize --plot" else work)),
        option,
        ["No space left on device"],
    )
    assert seen, "the writer was not reached"
    assert _files(work) == before


def test_a_full_disk_keeps_unrelated_files_of_a_forced_folder(tmp_path, monkeypatch):
    out = tmp_path / "out"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    _disk_full(monkeypatch)
    _check_refused(invoke(*NCAP, "--out", out, "--force"), "--out", ["No space left on device"])
    assert [p.name for p in out.iterdir()] == ["notes.txt"]


def test_a_sweep_full_midway_keeps_its_batches_for_resume(tmp_path, monkeypatch):
    spec, out = _spec(tmp_path), tmp_path / "out"
    real = vrusim.io.atomic.run_writer
    writes: list[Path] = []

    def full_at_third_batch(write, temp: Path) -> None:
        if temp.name.startswith(".chunk-000002"):
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        writes.append(temp)
        real(write, temp)

    monkeypatch.setattr(vrusim.io.atomic, "run_writer", full_at_third_batch)
    _check_refused(invoke("sweep", spec, "--out", out, "--workers", "1", "--quiet"), "--out", ["No space left"])
    assert sorted(p.name for p in (out / "chunks").iterdir()) == ["chunk-000000.parquet", "chunk-000001.parquet"]
    monkeypatch.setattr(vrusim.io.atomic, "run_writer", real)
    resumed = invoke("sweep", "--out", out, "--resume", "--workers", "1", "--json")
    assert resumed.exit_code == 0, resumed.output
    assert json.loads(resumed.stdout)["batches_run"] == 2


@pytest.mark.parametrize("scheduler", ["nonsense", "tcp://host:notaport", "foo://bar:1", "tcp://127.0.0.1:1", " "])
def test_a_bad_scheduler_writes_nothing_and_the_retry_works(tmp_path, monkeypatch, scheduler):
    pytest.importorskip("distributed")
    monkeypatch.setattr(vrusim.sweep.execute, "CONNECT_TIMEOUT_S", 1)
    spec, out = _spec(tmp_path), tmp_path / "out"
    _check_refused(invoke("sweep", spec, "--out", out, "--scheduler", scheduler), "--scheduler", [])
    assert not out.exists()
    retry = invoke("sweep", spec, "--out", out, "--workers", "1", "--quiet")
    assert retry.exit_code == 0, retry.output


def test_a_new_sweep_failing_before_its_first_batch_removes_only_what_it_made(tmp_path, monkeypatch):
    spec, out = _spec(tmp_path), tmp_path / "out"
    out.mkdir()  # existed before: stays

    def refused(task):
        raise UserInputError("planner: refused")

    monkeypatch.setattr("vrusim.sweep.execute.run_chunk", refused)
    assert_user_error(invoke("sweep", spec, "--out", out, "--workers", "1", "--quiet"), "planner: refused")
    assert out.is_dir() and list(out.iterdir()) == []
    assert_user_error(invoke("sweep", spec, "--out", tmp_path / "a" / "b", "--workers", "1"), "planner: refused")
    assert not (tmp_path / "a").exists()


@pytest.mark.parametrize("base", ["scen\0ario.yaml", "x" * 300 + ".yaml"])
def test_a_sweep_spec_base_the_os_cannot_use_names_the_field(tmp_path, base):
    spec = tmp_path / "sweep.yaml"
    spec.write_text(yaml.safe_dump({**SPEC, "base": base}))
    result = invoke("sweep", spec, "--out", tmp_path / "out")
    _check_refused(result, "base", ["as a file name"])
    assert "\0" not in result.output and not (tmp_path / "out").exists()


@pytest.mark.parametrize("source", ["x" * 5000, "CPNA-" + "a" * 300, "a\0b.yaml"])
def test_a_source_the_os_cannot_use_is_one_message(source):
    _check_refused(invoke("run", source), "SOURCE", [])


def test_shown_paths_are_short_and_keep_both_ends():
    long = "/start/" + "m" * 500 + "/end.csv"
    text = shown(long)
    assert len(text) == SHOWN_CHARS and text.startswith("/start/") and text.endswith("/end.csv")
    assert shown("a\0b") == "a\\x00b" and shown("short.csv") == "short.csv"


def test_the_api_checks_name_their_culprit(tmp_path):
    with pytest.raises(UserInputError, match=r"^trace: .*File name too long"):
        check_output_file(tmp_path / ("t" * 300 + ".csv"), "trace")
    with pytest.raises(UserInputError, match=r"^out: .*exists and is not a folder"):
        (tmp_path / "f").write_text("")
        check_output_folder(tmp_path / "f", "out")
    assert check_output_folder(tmp_path / "new" / "deeper", "out") == tmp_path / "new" / "deeper"
    assert not (tmp_path / "new").exists()
