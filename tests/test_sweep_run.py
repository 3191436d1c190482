"""Running sweeps: identical results on 1 or 2 workers and on a Dask cluster, resumable store, exactly once."""

from __future__ import annotations

import hashlib
import json
import os
import re
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.parquet as pq
import pytest
import yaml

from cli_helpers import assert_user_error, invoke
from conftest import PAPER_DIR, REPO_ROOT
from vrusim.engine.simulate import simulate
from vrusim.metrics.summary import summary_rows
from vrusim.ncap.grid import run_tests, select
from vrusim.sweep import execute
from vrusim.sweep.design import make_design
from vrusim.sweep.execute import cpu_count
from vrusim.sweep.plan import VariantBuilder, make_plan
from vrusim.sweep.runner import local_workers, preflight, run_sweep
from vrusim.sweep.spec import load_spec
from vrusim.sweep.store import SweepStore, chunk_name, write_parquet

SPEC = {
    "name": "test-sweep",
    "base": str(PAPER_DIR / "pedestrian_crossing.yaml"),
    "set": {"v2x.enabled": True, "sim.duration_s": 8.0},
    "parameters": {
        "ego.cruise_speed_mps": {"uniform": [10.0, 18.0]},
        "v2x.channel": ["ideal", "lossy", "bursty"],
        "vrus[0].top_speed_mps": {"truncated_normal": [1.5, 0.4, 0.8, 2.5]},
    },
    "samples": 40,
    "seed": 3,
    "batch_size": 20,
}


def write_spec(folder: Path, **changes) -> Path:
    path = folder / "spec.yaml"
    path.write_text(yaml.safe_dump({**SPEC, **changes}))
    return path


def results(folder: Path) -> pa.Table:
    return SweepStore(folder).read()


@pytest.fixture(scope="module")
def reference(tmp_path_factory) -> pa.Table:
    """The test sweep run in this process, uninterrupted."""
    folder = tmp_path_factory.mktemp("reference")
    run_sweep(load_spec(write_spec(folder)), folder / "out", workers=1)
    return results(folder / "out")


def sweep_command(*args) -> list[str]:
    return [sys.executable, "-m", "vrusim", "sweep", *map(str, args)]


def test_rows_hold_the_design_and_the_results_without_nan(reference):
    assert reference.num_rows == 120
    assert reference.column("variant").to_pylist() == list(range(120))
    for name in ("seed", "ego.cruise_speed_mps", "v2x.channel", "vrus[0].top_speed_mps", "outcome", "min_ttc_s"):
        assert name in reference.column_names
    for name in reference.column_names:
        column = reference.column(name)
        if pa.types.is_floating(column.type):
            assert not pc.any(pc.is_nan(column)).as_py(), name
    assert set(reference.column("outcome").to_pylist()) <= {"collision", "avoided", "stalled", "incomplete"}
    assert reference.column("collided").null_count == 0


def test_rows_equal_running_the_variants_directly(reference, tmp_path):
    """The stored numbers are those of the engine on the same scenarios, built the slow way."""
    plan = make_plan(load_spec(write_spec(tmp_path)))
    design = {
        name: reference.column(name).to_pylist() for name in ("variant", "seed", *[p.path for p in plan.parameters])
    }
    rows = [0, 41, 119]
    scenarios = VariantBuilder(plan).build(design, rows)
    direct = summary_rows(simulate(scenarios))
    for row, summary in zip(rows, direct, strict=True):
        assert scenarios[rows.index(row)].sim.seed == reference.column("seed")[row].as_py()
        assert reference.column("collided")[row].as_py() == summary["collided"]
        stored = reference.column("min_ttc_s")[row].as_py()
        assert (stored is None and summary["min_ttc_s"] is None) or round(stored, 6) == summary["min_ttc_s"]
        assert round(reference.column("safety")[row].as_py(), 4) == summary["safety"]


def test_two_local_workers_give_identical_results(reference, tmp_path):
    run_sweep(load_spec(write_spec(tmp_path)), tmp_path / "out", workers=2)
    assert results(tmp_path / "out").equals(reference)


def test_batch_size_does_not_change_results(reference, tmp_path):
    run_sweep(load_spec(write_spec(tmp_path)), tmp_path / "out", workers=1, batch_size=7)
    assert results(tmp_path / "out").equals(reference)
    assert len(SweepStore(tmp_path / "out").chunk_files()) == 18


def test_dask_local_cluster_gives_identical_results(reference, tmp_path):
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1", dashboard_address=None
    ) as cluster:
        completed = subprocess.run(
            sweep_command(
                write_spec(tmp_path), "--out", tmp_path / "out", "--scheduler", cluster.scheduler_address, "--quiet"
            ),
            capture_output=True,
            text=True,
            timeout=300,
        )
    assert completed.returncode == 0, completed.stderr
    assert results(tmp_path / "out").equals(reference)


def test_sigkill_then_resume_gives_every_variant_exactly_once(reference, tmp_path):
    spec = write_spec(tmp_path, batch_size=4)
    out = tmp_path / "out"
    process = subprocess.Popen(
        sweep_command(spec, "--out", out, "--workers", "2", "--quiet"),
        start_new_session=True,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    store = SweepStore(out)
    deadline = time.monotonic() + 120
    while len(store.finished()) < 3 and time.monotonic() < deadline and process.poll() is None:
        time.sleep(0.02)
    os.killpg(process.pid, signal.SIGKILL)
    process.wait()
    finished = len(store.finished())
    assert 3 <= finished < 30, finished  # killed mid-way
    completed = subprocess.run(
        sweep_command("--out", out, "--resume", "--quiet", "--json"), capture_output=True, text=True, timeout=300
    )
    assert completed.returncode == 0, completed.stderr
    outcome = json.loads(completed.stdout)
    assert outcome["batches_reused"] == finished and outcome["batches_run"] == 30 - finished
    ids = store.variant_ids()
    assert sorted(ids.tolist()) == list(range(120))
    assert results(out).equals(reference)
    assert not list(store.chunks.glob(".*"))  # no temporary file left


def test_ctrl_c_stops_cleanly_and_resume_finishes(tmp_path):
    # one variant a batch, 300 batches: seconds of work, so the signal cannot come after the last one (30 batches
    # of 4 once ended in 0.2 s, before it)
    spec = write_spec(tmp_path, batch_size=1, samples=100)
    out = tmp_path / "out"
    process = subprocess.Popen(
        sweep_command(spec, "--out", out, "--workers", "1", "--quiet"), stderr=subprocess.PIPE, text=True
    )
    store = SweepStore(out)
    deadline = time.monotonic() + 120
    while len(store.finished()) < 2 and time.monotonic() < deadline:
        time.sleep(0.02)
    process.send_signal(signal.SIGINT)
    _, stderr = process.communicate(timeout=60)
    assert process.returncode == 130, stderr
    assert "continue with --resume" in stderr and "Traceback" not in stderr
    assert len(store.finished()) < 300
    run_sweep(None, out, resume=True)
    uninterrupted = tmp_path / "uninterrupted"
    run_sweep(load_spec(spec), uninterrupted, workers=1, batch_size=100)
    assert results(out).num_rows == 300
    assert results(out).equals(results(uninterrupted))


def test_a_dying_worker_is_replaced_and_its_batch_rerun(tmp_path):
    spec = write_spec(
        tmp_path,
        set={"planner": {"name": "crash_once_planner:CrashOnce", "params": {}}},
        parameters={"ego.cruise_speed_mps": [8.0, 10.0, 12.0, 14.0]},
        samples=1,
        batch_size=1,
    )
    env = {
        **os.environ,
        "VRUSIM_CRASH_MARKER": str(tmp_path / "crashed"),
        "PYTHONPATH": os.pathsep.join([str(REPO_ROOT / "tests"), os.environ.get("PYTHONPATH", "")]),
    }
    completed = subprocess.run(
        sweep_command(spec, "--out", tmp_path / "out", "--workers", "2", "--quiet"),
        capture_output=True,
        text=True,
        env=env,
        timeout=300,
    )
    assert completed.returncode == 0, completed.stderr
    assert (tmp_path / "crashed").exists()
    assert sorted(SweepStore(tmp_path / "out").variant_ids().tolist()) == [0, 1, 2, 3]


def test_resume_reruns_exactly_the_missing_batches(reference, tmp_path):
    out = tmp_path / "out"
    run_sweep(load_spec(write_spec(tmp_path)), out)
    store = SweepStore(out)
    (store.chunks / chunk_name(2)).unlink()
    (store.chunks / ".chunk-000003.parquet.abc.tmp").write_bytes(b"half")
    outcome = run_sweep(None, out, resume=True)
    assert (outcome.chunks_run, outcome.chunks_reused) == (1, 5)
    assert results(out).equals(reference)
    assert run_sweep(None, out, resume=True).chunks_run == 0


def test_resume_warns_when_the_code_changed(tmp_path):
    spec = write_spec(tmp_path, samples=1, parameters={"ego.cruise_speed_mps": [12.0, 14.0]}, batch_size=1)
    out = tmp_path / "out"
    run_sweep(load_spec(spec), out)
    (SweepStore(out).chunks / chunk_name(1)).unlink()
    manifest = json.loads((out / "manifest.json").read_text())
    manifest["code"]["source_sha256"] = "0" * 64
    (out / "manifest.json").write_text(json.dumps(manifest))
    result = invoke("sweep", "--out", out, "--resume", "--quiet")
    assert result.exit_code == 0, result.output
    assert "Warning: the code changed since the sweep started" in result.stderr
    manifest["plan"]["seed"] = 99  # an edited plan no longer matches its digest
    (out / "manifest.json").write_text(json.dumps(manifest))
    assert_user_error(invoke("sweep", "--out", out, "--resume"), "manifest.json", "digest")


def test_plugin_planner_code_is_recorded_and_a_change_warns_on_resume(tmp_path, monkeypatch):
    """vrusim's source digest does not cover a user's planner: its module file is hashed into the manifest."""
    plugin = tmp_path / "plugins" / "my_hold_planner.py"
    plugin.parent.mkdir()
    plugin.write_text(
        "from vrusim.planners.base import HoldSpeedPlanner\n\n\nclass Hold(HoldSpeedPlanner):\n    pass\n"
    )
    monkeypatch.syspath_prepend(str(plugin.parent))
    spec = write_spec(
        tmp_path,
        set={"planner": {"name": "my_hold_planner:Hold", "params": {}}, "sim.duration_s": 4.0},
        parameters={"ego.cruise_speed_mps": [12.0, 14.0], "planner.name": ["fsm", "my_hold_planner:Hold"]},
        samples=1,
        batch_size=2,
    )
    out = tmp_path / "out"
    assert run_sweep(load_spec(spec), out).warnings == []
    recorded = json.loads((out / "manifest.json").read_text())["code"]["planner_plugins"]
    assert recorded == [
        {
            "planner": "my_hold_planner:Hold",
            "module": "my_hold_planner",
            "file": str(plugin),
            "sha256": hashlib.sha256(plugin.read_bytes()).hexdigest(),
        }
    ]
    (SweepStore(out).chunks / chunk_name(1)).unlink()
    assert run_sweep(None, out, resume=True).warnings == []  # unchanged plug-in: no warning
    (SweepStore(out).chunks / chunk_name(1)).unlink()
    plugin.write_text(plugin.read_text() + "# tuned\n")
    warnings = run_sweep(None, out, resume=True).warnings
    assert len(warnings) == 1
    assert warnings[0].startswith("planner 'my_hold_planner:Hold': its module my_hold_planner (")
    assert "changed since the sweep started" in warnings[0]


def test_catalogue_sweep_matches_the_catalogue_run(tmp_path):
    path = tmp_path / "spec.yaml"
    path.write_text(
        yaml.safe_dump(
            {"catalogue": {"scenarios": ["CPNA-25", "CBLA-50"], "planner": "none", "protocol": "2023"}, "batch_size": 8}
        )
    )
    run_sweep(load_spec(path), tmp_path / "out")
    table = results(tmp_path / "out")
    catalogue = {
        row["test_id"]: row
        for row in run_tests(select(protocol="2023", codes=["CPNA-25", "CBLA-50"]), planner="none").rows
    }
    assert table.column("test").to_pylist() == list(catalogue)
    assert table.column("collided").to_pylist() == [row["collided"] for row in catalogue.values()]
    speeds = [row["impact_speed_mps"] for row in catalogue.values()]
    stored = [None if v is None else round(v, 6) for v in table.column("impact_ego_speed_mps").to_pylist()]
    assert stored == speeds and any(s is not None for s in speeds)


def test_cli_sweep_reports_and_refuses_to_overwrite(tmp_path):
    spec = write_spec(tmp_path, samples=2, parameters={"ego.cruise_speed_mps": [12.0, 14.0]})
    first = invoke("sweep", spec, "--out", tmp_path / "out", "--workers", "1", "--json")
    assert first.exit_code == 0, first.output
    assert json.loads(first.stdout)["variants"] == 4
    manifest = json.loads((tmp_path / "out" / "manifest.json").read_text())
    assert manifest["variants"] == 4 and manifest["code"]["source_sha256"]
    assert_user_error(invoke("sweep", spec, "--out", tmp_path / "out"), "--out", "already exists", "--resume")
    changed = write_spec(tmp_path, samples=3, parameters={"ego.cruise_speed_mps": [12.0, 14.0]})
    assert_user_error(invoke("sweep", changed, "--out", tmp_path / "out", "--resume"), "SPEC: differs")
    assert_user_error(invoke("sweep", "--out", tmp_path / "out", "--resume", "--batch-size", "3"), "--batch-size")


@pytest.mark.parametrize(
    ("changes", "names"),
    [
        ({"parameters": {"ego.speed": [1.0]}}, ["parameters: ego.speed", "unknown field"]),
        (
            {"parameters": {"vrus[0].top_speed_mps": {"uniform": [-1.0, 2.0]}}},
            ["variant", "vrus[0].top_speed_mps", "greater than or equal to 0"],
        ),
        ({"parameters": {"planner.params.emergency_decel_mps2": [-3.0]}}, ["planner.params.emergency_decel_mps2"]),
        ({"parameters": {"v2x.channel": ["ideal", "nonsense"]}}, ["v2x.channel", "unknown channel profile"]),
        ({"base": "missing.yaml"}, ["missing.yaml", "no such scenario file"]),
        ({"catalogue": {"scenarios": ["XYZ"]}, "base": None}, ["catalogue.scenarios", "XYZ"]),
    ],
)
def test_bad_sweeps_fail_before_anything_is_written(tmp_path, changes, names):
    data = {**SPEC, **changes}
    path = tmp_path / "spec.yaml"
    path.write_text(yaml.safe_dump({k: v for k, v in data.items() if v is not None}))
    assert_user_error(invoke("sweep", path, "--out", tmp_path / "out", "--workers", "1"), *names)
    assert not (tmp_path / "out").exists()


def test_cli_option_errors(tmp_path):
    assert_user_error(invoke("sweep", tmp_path / "nope.yaml", "--out", tmp_path / "o"), "no such sweep spec file")
    assert_user_error(invoke("sweep", write_spec(tmp_path), "--workers", "-1", "--out", tmp_path / "o"), "--workers")
    assert_user_error(invoke("sweep", "--out", tmp_path / "o", "--resume"), "not a sweep results folder")
    assert_user_error(invoke("sweep", "--out", tmp_path / "o"), "SPEC")
    assert_user_error(
        invoke("sweep", write_spec(tmp_path), "--out", tmp_path / "o", "--scheduler", "tcp://127.0.0.1:1"),
        "--scheduler",
    )


def test_dry_run_plans_and_checks_without_writing(tmp_path):
    result = invoke("sweep", write_spec(tmp_path), "--out", tmp_path / "out", "--dry-run", "--json")
    assert result.exit_code == 0, result.output
    plan = json.loads(result.stdout)
    assert (plan["variants"], plan["grid_points"], plan["batches"]) == (120, 3, 6)
    speed = next(p for p in plan["parameters"] if p["name"] == "ego.cruise_speed_mps")
    assert 10.0 <= speed["drawn_min"] < speed["drawn_max"] < 18.0
    assert plan["variants_checked"] == 120  # small sweeps are checked in full
    assert plan["correlations"] == []
    assert not (tmp_path / "out").exists()
    pair = ["ego.cruise_speed_mps", "vrus[0].top_speed_mps"]
    correlated = write_spec(tmp_path, correlation=[{"between": pair, "rho": 0.8}], samples=400)
    result = invoke("sweep", correlated, "--out", tmp_path / "out", "--dry-run")
    assert result.exit_code == 0, result.output
    shown = re.search(
        r"correlation ego.cruise_speed_mps ~ vrus\[0\].top_speed_mps: rho \+0.8  drawn rank "
        r"correlation \+(0\.\d+)",
        result.stdout,
    )
    assert shown is not None and 0.7 < float(shown.group(1)) < 0.85, result.stdout
    bad = write_spec(tmp_path, parameters={"vrus[0].top_speed_mps": {"uniform": [-1.0, 2.0]}})
    assert_user_error(invoke("sweep", bad, "--dry-run"), "vrus[0].top_speed_mps")


def test_automatic_workers_run_compiled_batches_in_this_process(tmp_path):
    """0 workers: a sweep whose variants all run the compiled step stays in this process (threads on every
    core); one that needs the per-step path (here a VRU motion model without a compiled step) gets a process per
    core; a number given is kept."""
    plan = make_plan(load_spec(write_spec(tmp_path)))
    compiled = preflight(plan, make_design(plan))
    assert compiled.compiled and compiled.checked > 0
    cubic = {**SPEC["set"], "vrus[0].motion": "cubic"}
    plan = make_plan(load_spec(write_spec(tmp_path, set=cubic)))
    assert not preflight(plan, make_design(plan)).compiled
    assert local_workers(0, compiled=True) == 1
    assert local_workers(0, compiled=False) == cpu_count()
    assert local_workers(3, compiled=True) == local_workers(3, compiled=False) == 3


def test_automatic_workers_give_the_same_results(reference, tmp_path):
    run_sweep(load_spec(write_spec(tmp_path)), tmp_path / "out", workers=0)
    assert results(tmp_path / "out").equals(reference)


class _Batches:
    """A stand-in for `run_chunk` that records which batches ran at once, and fails on batch `fail`."""

    def __init__(self, fail: int | None = None) -> None:
        self.fail, self.lock, self.running, self.most, self.started = fail, threading.Lock(), 0, 0, []
        self.first_two = threading.Barrier(2, timeout=30)  # batches 0 and 1 wait for each other: both run at once

    def __call__(self, task: int) -> int:
        with self.lock:
            self.running += 1
            self.most = max(self.most, self.running)
            self.started.append(task)
        if task < 2:
            self.first_two.wait()
        time.sleep(0.01)
        with self.lock:
            self.running -= 1
        if task == self.fail:
            raise RuntimeError(f"batch {task} failed")
        return task * 10


def test_in_process_batches_run_two_at_once_and_are_stored_in_order(monkeypatch):
    batches = _Batches()
    monkeypatch.setattr(execute, "run_chunk", batches)
    stored = []
    execute.run_in_process(range(7), lambda task, table: stored.append((task, table, threading.current_thread())))
    assert [(task, table) for task, table, _ in stored] == [(i, i * 10) for i in range(7)]
    assert {thread for _, _, thread in stored} == {threading.main_thread()}  # stored by the calling thread
    assert batches.most == execute.IN_FLIGHT_IN_PROCESS == 2


def test_after_an_in_process_batch_fails_no_new_batch_starts(monkeypatch):
    batches = _Batches(fail=2)
    monkeypatch.setattr(execute, "run_chunk", batches)
    stored = []
    with pytest.raises(RuntimeError, match="batch 2 failed"):
        execute.run_in_process(range(9), lambda task, table: stored.append(task))
    assert stored == [0, 1]
    assert sorted(batches.started) in ([0, 1, 2], [0, 1, 2, 3])  # the one in flight beside it may have started
    assert batches.running == 0  # it was waited for


def test_parquet_files_dictionary_encode_only_text_columns(tmp_path):
    """Numbers are stored plainly (they rarely repeat; a dictionary only slows the write), text with a
    dictionary, and the table reads back unchanged."""
    table = pa.table(
        {
            "x": pa.array([1.5, 2.5, 1.5]),
            "name": pa.array(["a", "b", "a"]),
            "params": pa.array(['{"k": 1}', None, '{"k": 1}'], type=pa.large_string()),
        }
    )
    write_parquet(table, tmp_path / "t.parquet")
    columns = pq.ParquetFile(tmp_path / "t.parquet").metadata.row_group(0)
    encodings = {columns.column(i).path_in_schema: columns.column(i).encodings for i in range(3)}
    assert "RLE_DICTIONARY" not in encodings["x"]
    assert "RLE_DICTIONARY" in encodings["name"] and "RLE_DICTIONARY" in encodings["params"]
    assert pq.read_table(tmp_path / "t.parquet").equals(table)
