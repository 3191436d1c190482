"""`vrusim summarize`: sweep results read back with DuckDB and checked against plain NumPy; errors; plots."""

from __future__ import annotations

import json
import math
import tempfile
from collections import Counter
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from matplotlib.colors import to_rgb
from matplotlib.image import imread
from matplotlib.pyplot import get_cmap

from cli_helpers import assert_user_error, invoke
from vrusim.studies.compare import wilson_interval
from vrusim.sweep.summarize import summarize
from vrusim.viz.sensitivity import group_axis, sensitivity_figure, write_figure

SPEED = "ego.cruise_speed_mps"  # continuous: binned
WALK = "vrus[0].top_speed_mps"  # three values: grouped exactly
LATENCY = "v2x.channel.latency_s"  # float parameter with NULLs
METRICS = ("min_ttc_s", "impact_ego_speed_mps", "safety", "efficiency", "comfort", "peak_decel_mps2")
Z95 = 1.959964


# ----------------------------------------------------------------------------------------------- fixtures


def write_results(
    root: Path,
    chunks: list[dict[str, pa.Array | list]],
    parameters: list[str],
    expected_chunks: int | None = None,
) -> Path:
    """A results directory: manifest.json and one Parquet file per chunk (column name → values)."""
    (root / "chunks").mkdir(parents=True, exist_ok=True)
    manifest = {
        "format": "vrusim-sweep/1",
        "name": "synthetic",
        "variants": sum(len(next(iter(chunk.values()))) for chunk in chunks),
        "batch_size": 40,
        "chunks": len(chunks) if expected_chunks is None else expected_chunks,
        "seed": 7,
        "parameters": [{"name": name, "kind": "uniform"} for name in parameters],
        "spec": {},
        "code": {},
    }
    (root / "manifest.json").write_text(json.dumps(manifest))
    for index, chunk in enumerate(chunks):
        pq.write_table(pa.table(chunk), root / "chunks" / f"chunk-{index:06d}.parquet")
    return root


def _nullable(values: np.ndarray, present: np.ndarray) -> pa.Array:
    return pa.array(values, type=pa.float64(), mask=~present)


def synthetic_chunks(n_chunks: int = 3, rows: int = 40, seed: int = 1) -> list[dict]:
    """Known random content: a continuous and a three-valued parameter, NULL metrics, a `test` column."""
    rng = np.random.default_rng(seed)
    chunks = []
    for c in range(n_chunks):
        speed = rng.uniform(5.0, 20.0, rows)
        walk = rng.choice([1.0, 1.5, 2.0], rows)
        collided = rng.random(rows) < (speed - 5.0) / 15.0
        latency = rng.uniform(0.0, 0.5, rows)
        chunks.append(
            {
                "variant": np.arange(c * rows, (c + 1) * rows, dtype=np.int64),
                "seed": rng.integers(0, 1000, rows),
                "test": rng.choice(["CPNA-25", "CPFA-50"], rows),
                SPEED: speed,
                WALK: walk,
                LATENCY: _nullable(latency, rng.random(rows) > 0.2),
                "outcome": np.where(collided, "collision", rng.choice(["avoided", "stalled", "incomplete"], rows)),
                "collided": collided,
                "min_ttc_s": _nullable(rng.uniform(0.0, 4.0, rows), ~collided),
                "impact_ego_speed_mps": _nullable(rng.uniform(0.0, 10.0, rows), collided),
                "safety": rng.uniform(0.0, 1.0, rows),
                "efficiency": rng.uniform(0.0, 1.0, rows),
                "comfort": rng.uniform(0.0, 1.0, rows),
                "peak_decel_mps2": rng.uniform(0.0, 9.0, rows),
            }
        )
    return chunks


def frame(chunks: list[dict]) -> dict[str, np.ndarray]:
    """All chunks as columns of float/object arrays; NULL → NaN (floats) or None."""
    out = {}
    for name in chunks[0]:
        parts = []
        for chunk in chunks:
            values = chunk[name]
            parts.append(values.to_numpy(zero_copy_only=False) if isinstance(values, pa.Array) else np.asarray(values))
        out[name] = np.concatenate(parts)
    return out


@pytest.fixture
def results(tmp_path) -> tuple[Path, dict[str, np.ndarray]]:
    chunks = synthetic_chunks()
    return write_results(tmp_path / "sweep", chunks, [SPEED, WALK, LATENCY]), frame(chunks)


# ----------------------------------------------------------------------------------------------- independent maths


def wilson_by_quadratic(k: int, n: int, z: float = Z95) -> tuple[float, float]:
    """Wilson (1927): the p with (p̂ − p)² = z² p (1 − p) / n, solved as a quadratic in p."""
    p_hat = k / n
    a = 1 + z * z / n
    b = -(2 * p_hat + z * z / n)
    c = p_hat * p_hat
    roots = np.roots([a, b, c]).real
    return float(max(0.0, roots.min())), float(min(1.0, roots.max()))


def expected_stats(values: np.ndarray) -> dict[str, float | int | None]:
    present = values[~np.isnan(values)]
    if present.size == 0:
        return dict.fromkeys(("mean", "std", "min", "p5", "median", "p95", "max")) | {"count": 0}
    return {
        "count": int(present.size),
        "mean": float(np.mean(present)),
        "std": float(np.std(present, ddof=1)) if present.size > 1 else None,
        "min": float(present.min()),
        "p5": float(np.quantile(present, 0.05)),  # numpy default: linear interpolation = quantile_cont
        "median": float(np.quantile(present, 0.5)),
        "p95": float(np.quantile(present, 0.95)),
        "max": float(present.max()),
    }


def assert_stats(actual: dict, expected: dict) -> None:
    assert actual["count"] == expected["count"]
    for name in ("mean", "std", "min", "p5", "median", "p95", "max"):
        if expected[name] is None:
            assert actual[name] is None, name
        else:
            assert actual[name] == pytest.approx(expected[name], rel=1e-9, abs=1e-12), name


def assert_outcome(group: dict, collided: np.ndarray, outcome: np.ndarray | None = None) -> None:
    runs, collisions = int(collided.size), int(collided.sum())
    assert (group["runs"], group["collisions"]) == (runs, collisions)
    if outcome is not None:
        assert group["stalled"] == int((outcome == "stalled").sum()) > 0
        assert group["incomplete"] == int((outcome == "incomplete").sum()) > 0
    assert group["collision_probability"] == pytest.approx(collisions / runs)
    assert group["collision_probability_95"] == pytest.approx(wilson_by_quadratic(collisions, runs), abs=1e-9)


def strict_json(text: str):
    """Parse JSON, refusing NaN and infinities."""

    def refuse(constant):
        raise AssertionError(f"{constant} in JSON output")

    return json.loads(text, parse_constant=refuse)


# ----------------------------------------------------------------------------------------------- numbers


def test_overall_numbers_equal_numpy(results):
    directory, data = results
    summary = summarize(directory, metrics=METRICS)
    assert summary["chunks"] == {"found": 3, "expected": 3, "partial": False}
    assert summary["status"] == "3 of 3 chunks"
    assert summary["groups"] == []
    assert_outcome(summary["overall"], data["collided"], data["outcome"])
    for metric in METRICS:
        assert_stats(summary["overall"]["metrics"][metric], expected_stats(data[metric].astype(float)))


def test_default_metrics_and_metric_discovery(results):
    directory, _ = results
    summary = summarize(directory)
    assert summary["metrics"] == ["min_ttc_s", "impact_ego_speed_mps", "safety", "efficiency", "comfort"]
    result = invoke("summarize", directory, "--metrics", "bogus")
    # every non-parameter numeric column is a metric; parameters, ids and the outcome are not
    listed = result.output.split("expected one of:")[1]
    assert "peak_decel_mps2" in listed and "min_ttc_s" in listed
    for name in (SPEED, LATENCY, "variant", "seed", "collided", "test"):
        assert name not in listed


def test_grouped_binned_and_exact_equal_numpy(results):
    directory, data = results
    bins = 4
    summary = summarize(directory, by=[SPEED, WALK], bins=bins, metrics=["min_ttc_s", "safety"])
    speed_info, walk_info = summary["by"]
    assert speed_info["binned"] and not walk_info["binned"]
    assert walk_info["distinct"] == 3 and speed_info["distinct"] == data[SPEED].size
    edges = np.linspace(data[SPEED].min(), data[SPEED].max(), bins + 1)
    assert speed_info["edges"] == pytest.approx(edges, rel=1e-15)
    index = np.clip(np.searchsorted(edges, data[SPEED], side="right") - 1, 0, bins - 1)

    seen = set()
    for group in summary["groups"]:
        key_speed, key_walk = group["key"][SPEED], group["key"][WALK]
        b = key_speed["bin"]
        assert (key_speed["low"], key_speed["high"]) == pytest.approx((edges[b], edges[b + 1]))
        assert key_speed["centre"] == pytest.approx((edges[b] + edges[b + 1]) / 2)
        members = (index == b) & (data[WALK] == key_walk)
        assert members.any()
        assert_outcome(group, data["collided"][members])
        for metric in ("min_ttc_s", "safety"):
            assert_stats(group["metrics"][metric], expected_stats(data[metric][members].astype(float)))
        seen.add((b, key_walk))
    expected_groups = {(int(b), float(w)) for b, w in zip(index, data[WALK], strict=True)}
    assert seen == expected_groups
    assert sum(group["runs"] for group in summary["groups"]) == data[SPEED].size
    # ordered by bin, then value
    keys = [(g["key"][SPEED]["bin"], g["key"][WALK]) for g in summary["groups"]]
    assert keys == sorted(keys)


def test_nulls_form_their_own_group_last_and_strings_group_exactly(results):
    directory, data = results
    summary = summarize(directory, by=[LATENCY, "test"], bins=2, metrics=[])
    latency = data[LATENCY].astype(float)
    last = summary["groups"][-1]
    assert last["key"][LATENCY] is None
    null_groups = [g for g in summary["groups"] if g["key"][LATENCY] is None]
    assert sum(g["runs"] for g in null_groups) == int(np.isnan(latency).sum())
    assert {g["key"]["test"] for g in summary["groups"]} == {"CPNA-25", "CPFA-50"}
    for group in null_groups:
        members = np.isnan(latency) & (data["test"] == group["key"]["test"])
        assert_outcome(group, data["collided"][members])


def test_a_metric_without_values_in_a_group_gives_nulls_not_nan(tmp_path):
    chunk = {
        "variant": np.arange(4, dtype=np.int64),
        "seed": np.zeros(4, dtype=np.int64),
        "p": [0.0, 0.0, 1.0, 1.0],
        "outcome": ["avoided"] * 4,
        "collided": [False] * 4,
        "min_ttc_s": _nullable(np.array([1.0, 2.0, 0.0, 0.0]), np.array([True, True, False, False])),
        "steps": np.array([10, 20, 30, 40], dtype=np.int32),  # integer metrics count too
    }
    directory = write_results(tmp_path / "r", [chunk], ["p"])
    result = invoke("summarize", directory, "--by", "p", "--metrics", "min_ttc_s,steps", "--json")
    assert result.exit_code == 0, result.output
    document = strict_json(result.stdout)
    empty = document["groups"][1]["metrics"]["min_ttc_s"]
    assert empty == {"count": 0, "mean": None, "std": None, "min": None, "p5": None, "median": None,
                     "p95": None, "max": None}  # fmt: skip
    assert document["groups"][0]["metrics"]["min_ttc_s"]["std"] == pytest.approx(math.sqrt(0.5))
    assert document["groups"][1]["metrics"]["steps"]["mean"] == 35.0
    assert document["overall"]["collision_probability_95"] == pytest.approx(wilson_by_quadratic(0, 4))


# ----------------------------------------------------------------------------------------------- properties


@settings(max_examples=40, deadline=None)
@given(
    values=st.lists(
        st.one_of(st.floats(-1e3, 1e3, allow_nan=False), st.integers(-5, 5).map(float)), min_size=1, max_size=30
    ),
    bins=st.integers(1, 6),
)
@example(values=[float(v) for v in range(11)], bins=5)  # values on the edges 0, 2, …, 10: [2, 4) holds 2 and 3
def test_binning_puts_every_value_in_its_bin(values, bins):
    """Bins partition the runs; every value lies in its bin's [low, high]; few distinct values group exactly."""
    x = np.array(values)
    rows = len(values)
    chunk = {
        "variant": np.arange(rows, dtype=np.int64),
        "seed": np.zeros(rows, dtype=np.int64),
        "x": x,
        "collided": np.zeros(rows, dtype=bool),
        "m": x,  # the metric repeats the parameter: each group's min and max show its members
    }
    with tempfile.TemporaryDirectory() as folder:
        summary = summarize(write_results(Path(folder), [chunk], ["x"]), by=["x"], bins=bins, metrics=["m"])
    assert sum(group["runs"] for group in summary["groups"]) == rows
    distinct = np.unique(x)
    if distinct.size <= bins:
        assert Counter({g["key"]["x"]: g["runs"] for g in summary["groups"]}) == Counter(x.tolist())
        return
    edges = np.linspace(x.min(), x.max(), bins + 1)
    index = np.clip(np.searchsorted(edges, x, side="right") - 1, 0, bins - 1)
    assert Counter({g["key"]["x"]["bin"]: g["runs"] for g in summary["groups"]}) == Counter(index.tolist())
    for group in summary["groups"]:
        key, stats = group["key"]["x"], group["metrics"]["m"]
        assert key["low"] <= stats["min"] and stats["max"] <= key["high"]
        assert key["low"] <= key["centre"] <= key["high"]


@given(n=st.integers(1, 2000), data=st.data())
def test_wilson_interval_solves_the_score_equation(n, data):
    k = data.draw(st.integers(0, n))
    low, high = wilson_interval(k, n)
    assert 0.0 <= low <= k / n <= high <= 1.0
    assert (low, high) == pytest.approx(wilson_by_quadratic(k, n), abs=1e-9)


# ----------------------------------------------------------------------------------------------- CLI


def test_cli_table_and_json(results):
    directory, data = results
    table = invoke("summarize", directory, "--by", WALK)
    assert table.exit_code == 0, table.output
    assert "3 of 3 chunks" in table.output and "partial" not in table.output
    for value in ("1.5", "min_ttc_s", "comfort", "95 % interval"):
        assert value in table.output
    document = strict_json(invoke("summarize", directory, "--by", WALK, "--json").stdout)
    assert document["overall"]["runs"] == data[SPEED].size
    assert [g["key"][WALK] for g in document["groups"]] == [1.0, 1.5, 2.0]


def test_partial_sweep_is_summarised_and_says_so(tmp_path):
    chunks = synthetic_chunks(n_chunks=2)
    directory = write_results(tmp_path / "r", chunks, [SPEED, WALK], expected_chunks=5)
    # temporary files of a chunk being written are ignored (DuckDB's own glob would read the dot-file)
    pq.write_table(pa.table(synthetic_chunks(1, seed=9)[0]), directory / "chunks" / ".chunk-000002.parquet")
    (directory / "chunks" / ".chunk-000003.parquet.x1y2.tmp").write_bytes(b"half a file")
    result = invoke("summarize", directory)
    assert result.exit_code == 0, result.output
    assert "2 of 5 chunks (partial)" in result.output
    document = strict_json(invoke("summarize", directory, "--json").stdout)
    assert document["status"] == "2 of 5 chunks (partial)"
    assert document["chunks"] == {"found": 2, "expected": 5, "partial": True}
    assert document["overall"]["runs"] == 80


def _bad_manifest(tmp_path: Path) -> Path:
    directory = write_results(tmp_path / "r", synthetic_chunks(1), [SPEED])
    (directory / "manifest.json").write_text('{"format": "something-else/9", "parameters": []}')
    return directory


def _no_chunks(tmp_path: Path) -> Path:
    directory = write_results(tmp_path / "r", [], [SPEED])
    (directory / "chunks" / ".chunk-000000.parquet.tmp").write_bytes(b"")
    return directory


def _no_manifest(tmp_path: Path) -> Path:
    directory = write_results(tmp_path / "r", synthetic_chunks(1), [SPEED])
    (directory / "manifest.json").unlink()
    return directory


def _ok(tmp_path: Path) -> Path:
    return write_results(tmp_path / "r", synthetic_chunks(1), [SPEED, WALK])


@pytest.mark.parametrize(
    ("make", "args", "names"),
    [
        (lambda tmp: tmp / "missing", [], ["missing", "not found"]),
        (_no_manifest, [], ["manifest.json"]),
        (_bad_manifest, [], ["manifest.json", "format", "vrusim-sweep/1"]),
        (_no_chunks, [], ["no chunk files"]),
        (_ok, ["--by", "ego.speed"], ["--by", "'ego.speed'", SPEED, WALK]),
        (_ok, ["--by", " , "], ["--by"]),
        (_ok, ["--metrics", "ttc"], ["--metrics", "'ttc'", "min_ttc_s", "peak_decel_mps2"]),
        (_ok, ["--bins", "0"], ["--bins", "≥ 1"]),
        (_ok, ["--plot", "out.gif", "--x", SPEED], ["--plot", ".gif", ".png"]),
        (_ok, ["--plot", "out.png"], ["--plot", "--x"]),
        (_ok, ["--x", SPEED], ["--x", "--plot"]),
        (_ok, ["--plot", "out.png", "--x", "nope"], ["--x", "'nope'", WALK]),
        (_ok, ["--plot", "out.png", "--x", SPEED, "--y", SPEED], ["--y", "--x"]),
        (_ok, ["--plot", "out.png", "--x", SPEED, "--metric", "nope"], ["--metric", "'nope'", "safety"]),
        (_ok, ["--plot", "no-such-folder/out.png", "--x", SPEED], ["--plot", "no-such-folder"]),
    ],
)
def test_user_errors(tmp_path, monkeypatch, make, args, names):
    monkeypatch.chdir(tmp_path)
    result = invoke("summarize", make(tmp_path), *args)
    assert_user_error(result, *names)
    assert result.output.count("\n") == 1  # one line
    assert not list(tmp_path.glob("out.*"))


def test_unreadable_chunk_is_a_user_error(tmp_path):
    directory = _ok(tmp_path)
    (directory / "chunks" / "chunk-000001.parquet").write_bytes(b"not parquet")
    assert_user_error(invoke("summarize", directory), "chunks", "cannot read")


# ----------------------------------------------------------------------------------------------- plots


def _cells_results(tmp_path: Path) -> Path:
    """x ∈ {0, 1, 2} × y ∈ {10, 20}: every run at (2, 20) collides, none elsewhere, and (0, 20) has no runs."""
    cells = [(0.0, 10.0), (1.0, 10.0), (2.0, 10.0), (1.0, 20.0), (2.0, 20.0)]
    xs = np.repeat([c[0] for c in cells], 4)
    ys = np.repeat([c[1] for c in cells], 4)
    chunk = {
        "variant": np.arange(xs.size, dtype=np.int64),
        "seed": np.zeros(xs.size, dtype=np.int64),
        "a": xs,
        "b": ys,
        "collided": (xs == 2.0) & (ys == 20.0),
        "safety": xs / 2.0,
    }
    return write_results(tmp_path / "cells", [chunk], ["a", "b"])


def _pixel(image: np.ndarray, ax, x: float, y: float) -> np.ndarray:
    """RGB of the saved image at data point (x, y) of `ax` (display origin bottom-left, image top-left)."""
    px, py = ax.transData.transform((x, y))
    return image[round(image.shape[0] - py), round(px), :3]


def test_heat_map_pixels_show_the_probabilities(tmp_path):
    summary = summarize(_cells_results(tmp_path), by=["a", "b"], metrics=[])
    fig = sensitivity_figure(summary, "a", "b")
    path = write_figure(fig, tmp_path / "heat.png")
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    image = imread(path)
    ax = fig.axes[0]
    viridis = get_cmap("viridis")
    hot, cold = np.array(viridis(1.0)[:3]), np.array(viridis(0.0)[:3])
    assert _pixel(image, ax, 2.0, 20.0) == pytest.approx(hot, abs=0.02)
    for cell in ((0.0, 10.0), (1.0, 10.0), (2.0, 10.0), (1.0, 20.0)):
        assert _pixel(image, ax, *cell) == pytest.approx(cold, abs=0.02), cell
    assert _pixel(image, ax, 0.0, 20.0) == pytest.approx(to_rgb(ax.get_facecolor()), abs=0.02)  # no runs
    assert "P(collision)" in fig.axes[1].get_ylabel()  # the colour bar says what and in which unit


def test_heat_map_of_a_metric_mean(tmp_path):
    summary = summarize(_cells_results(tmp_path), by=["a", "b"], metrics=["safety"])
    fig = sensitivity_figure(summary, "a", "b", metric="safety")
    mesh = fig.axes[0].collections[0]
    values = np.ma.getdata(mesh.get_array()).reshape(2, 3)
    mask = np.ma.getmaskarray(mesh.get_array()).reshape(2, 3)
    assert mask.tolist() == [[False, False, False], [True, False, False]]
    assert values[~mask].tolist() == [0.0, 0.5, 1.0, 0.5, 1.0]
    assert group_axis(summary, "a").edges == [-0.5, 0.5, 1.5, 2.5]
    assert fig.axes[1].get_ylabel() == "mean safety (score, 0–1)"


def test_line_plot_data_is_the_binned_probability_and_wilson_band(results):
    directory, data = results
    summary = summarize(directory, by=[SPEED], bins=5, metrics=[])
    fig = sensitivity_figure(summary, SPEED)
    ax = fig.axes[0]
    line = ax.lines[0]
    edges = np.linspace(data[SPEED].min(), data[SPEED].max(), 6)
    index = np.clip(np.searchsorted(edges, data[SPEED], side="right") - 1, 0, 4)
    present = sorted(set(index.tolist()))
    centres = [(edges[b] + edges[b + 1]) / 2 for b in present]
    probabilities = [data["collided"][index == b].mean() for b in present]
    assert line.get_xdata() == pytest.approx(centres)
    assert line.get_ydata() == pytest.approx(probabilities)
    band = ax.collections[0].get_paths()[0].vertices
    for b, centre in zip(present, centres, strict=True):
        members = data["collided"][index == b]
        low, high = wilson_by_quadratic(int(members.sum()), int(members.size))
        at = band[np.isclose(band[:, 0], centre)][:, 1]
        assert np.isclose(at, low).any() and np.isclose(at, high).any()
    assert ax.get_xlabel().startswith(f"{SPEED} (m/s)")


def test_metric_line_plot_shows_mean_and_p5_p95(results):
    directory, data = results
    summary = summarize(directory, by=[WALK], metrics=["peak_decel_mps2"])
    fig = sensitivity_figure(summary, WALK, metric="peak_decel_mps2")
    ax = fig.axes[0]
    assert ax.lines[0].get_xdata().tolist() == [1.0, 1.5, 2.0]
    decel = data["peak_decel_mps2"]
    means = [decel[data[WALK] == w].mean() for w in (1.0, 1.5, 2.0)]
    assert ax.lines[0].get_ydata() == pytest.approx(means)
    band = ax.collections[0].get_paths()[0].vertices
    for w in (1.0, 1.5, 2.0):
        at = band[np.isclose(band[:, 0], w)][:, 1]
        assert np.isclose(at, np.quantile(decel[data[WALK] == w], 0.05)).any()
        assert np.isclose(at, np.quantile(decel[data[WALK] == w], 0.95)).any()
    assert ax.get_ylabel() == "mean peak_decel_mps2 (m/s²)"


@pytest.mark.parametrize(("suffix", "magic"), [(".png", b"\x89PNG"), (".svg", b"<?xml"), (".pdf", b"%PDF")])
def test_cli_writes_the_figure_in_the_suffix_format(results, tmp_path, suffix, magic):
    directory, _ = results
    out = tmp_path / f"plot{suffix.upper()}"
    result = invoke("summarize", directory, "--plot", out, "--x", SPEED, "--y", WALK, "--bins", "3")
    assert result.exit_code == 0, result.output
    assert out.read_bytes().startswith(magic)
    assert f"Plot written to {out}" in result.output.replace("\n", "")
    assert not [p for p in out.parent.iterdir() if p.name.startswith(".")]  # no temporary file left


def test_cli_plot_with_json_prints_only_json(results, tmp_path):
    directory, _ = results
    out = tmp_path / "p.png"
    result = invoke("summarize", directory, "--json", "--plot", out, "--x", WALK, "--metric", "safety")
    assert result.exit_code == 0, result.output
    strict_json(result.stdout)
    assert imread(out).shape[2] in (3, 4)


def test_two_long_grouping_parameters_fit_80_columns(tmp_path):
    """Two grouping parameters share one numbered column, long dotted paths break at dots and underscores, bin ranges
    wrap at spaces, and a metric table still too wide leaves out p5 / p95 and says so: nothing is cut with "…"."""
    from typer.testing import CliRunner

    from vrusim.cli.app import app

    chunks = synthetic_chunks()
    long_names = {SPEED: "ego.tracking.heading_gain_per_m", WALK: "v2x.channel.loss.probability"}
    renamed = [{long_names.get(name, name): values for name, values in chunk.items()} for chunk in chunks]
    directory = write_results(tmp_path / "r", renamed, list(long_names.values()))
    by = ",".join(long_names.values())
    result = CliRunner().invoke(app, ["summarize", str(directory), "--by", by, "--bins", "3"], env={"COLUMNS": "80"})
    assert result.exit_code == 0, result.output
    assert "…" not in result.output
    assert max(len(line) for line in result.output.splitlines()) <= 80
    for word in ("1: ego.", "heading_", "gain_per_m", "2: v2x.", "probability", "P(collision)", "95 % interval"):
        assert word in result.output, word
    assert " – " in result.output  # a bin's range, spaced so that it can wrap
    assert "p95" in result.output and "widen the terminal" not in result.output
    narrow = CliRunner().invoke(app, ["summarize", str(directory), "--by", by, "--bins", "3"], env={"COLUMNS": "64"})
    assert "p5 and p95: widen the terminal, or --json" in narrow.output and "…" not in narrow.output
    assert "Stalled /" in result.output and "widen the terminal" not in result.output.split("Collisions")[0]
    assert "stalled / incomplete runs: widen the terminal, or --json" in narrow.output
    assert max(len(line) for line in narrow.output.splitlines()) <= 64


def test_results_without_an_outcome_column_summarise_without_stall_counts(tmp_path):
    """Sweeps written before outcomes existed have no `outcome` column: stalled and incomplete are None (null in
    JSON, "–" in the table), the rest as before."""
    chunks = synthetic_chunks(n_chunks=1)
    for chunk in chunks:
        del chunk["outcome"]
    directory = write_results(tmp_path / "old", chunks, [SPEED, WALK, LATENCY])
    overall = summarize(directory)["overall"]
    assert overall["stalled"] is None and overall["incomplete"] is None
    assert_outcome(overall, frame(chunks)["collided"])
