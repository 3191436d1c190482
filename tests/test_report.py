"""HTML reports without a browser: self-contained, escaped, numbers equal the results, bad input refused."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest
import yaml

from cli_helpers import assert_user_error, invoke
from conftest import REPO_ROOT, minimal_scenario_dict
from report_helpers import external_references, read_report, same, wilson
from vrusim.report.charts import nice_ticks
from vrusim.report.html import Html, esc, script_json, tag

EXAMPLE = REPO_ROOT / "scenarios" / "examples" / "right_turn_cyclist.yaml"
NASTY = '<script>alert("x")</script> & <b>bold</b>'


@pytest.fixture(scope="module")
def run_report(tmp_path_factory) -> tuple[str, dict]:
    """The run report of the example scenario and its `vrusim run --json` row."""
    out = tmp_path_factory.mktemp("run") / "run.html"
    result = invoke("report", EXAMPLE, "--out", out)
    assert result.exit_code == 0, result.output
    row = json.loads(invoke("run", EXAMPLE, "--json").stdout)
    return out.read_text(encoding="utf-8"), row


def synthetic_sweep(root: Path, seed: int = 5, n: int = 60) -> dict[str, np.ndarray]:
    """A sweep results folder with one binned and one exact parameter; returns its columns."""
    rng = np.random.default_rng(seed)
    columns = {
        "variant": np.arange(n),
        "ego.cruise_speed_mps": rng.uniform(8.0, 18.0, n),
        "v2x.enabled": rng.integers(0, 2, n).astype(bool),
    }
    columns["collided"] = rng.uniform(size=n) < (columns["ego.cruise_speed_mps"] - 8.0) / 10.0
    columns["min_ttc_s"] = rng.uniform(0.0, 5.0, n)
    (root / "chunks").mkdir(parents=True)
    manifest = {"format": "vrusim-sweep/1", "name": NASTY, "variants": n, "chunks": 2, "seed": 1,
                "parameters": [{"name": "ego.cruise_speed_mps", "kind": "uniform"},
                               {"name": "v2x.enabled", "kind": "grid"}], "spec": {"name": NASTY}}  # fmt: skip
    (root / "manifest.json").write_text(json.dumps(manifest))
    for index, part in enumerate(np.array_split(np.arange(n), 2)):
        pq.write_table(
            pa.table({k: v[part] for k, v in columns.items()}), root / "chunks" / f"chunk-{index:06d}.parquet"
        )
    return columns


# ----------------------------------------------------------------------------------------------- building blocks


def test_escaping_building_blocks():
    assert esc(NASTY) == "&lt;script&gt;alert(&quot;x&quot;)&lt;/script&gt; &amp; &lt;b&gt;bold&lt;/b&gt;"
    assert tag("td", NASTY, title=NASTY).count("<") == 2  # only the td's own tags
    assert Html("<b>") + "<i>" == "<b>&lt;i&gt;"
    block = script_json({"name": "</script><script>alert(1)</script>"}, element_id="results")
    assert block.count("</script>") == 1 and json.loads(block[block.index(">") + 1 : -9])["name"].startswith("</")


def test_nice_ticks_cover_the_range():
    assert nice_ticks(0.0, 17.09, 9) == [0.0, 2.5, 5.0, 7.5, 10.0, 12.5, 15.0]
    assert nice_ticks(-2.1, 1.6, 5) == [-2.0, -1.0, 0.0, 1.0]


# ----------------------------------------------------------------------------------------------- run report


def test_run_report_is_self_contained(run_report):
    text, _ = run_report
    reader = read_report(text)
    assert external_references(text) == []
    assert not [attrs for tag_name, attrs in reader.tags if tag_name == "link"]
    policy = [a["content"] for t, a in reader.tags if t == "meta" and a.get("http-equiv") == "Content-Security-Policy"]
    assert policy and policy[0].startswith("default-src 'none'; img-src data:;")
    images = [attrs["src"] for tag_name, attrs in reader.tags if tag_name == "img"]
    assert len(images) == 2 and all(src.startswith("data:image/png;base64,") for src in images)


def test_run_report_numbers_equal_run_json(run_report):
    text, row = run_report
    reader = read_report(text)
    summary = reader.tables["summary"]
    scalars = {k: v for k, v in row.items() if not isinstance(v, dict | list)}
    assert set(summary) == set(scalars)
    for key, value in scalars.items():
        assert same(summary[key]["value"], value), key
    transitions = reader.tables["transitions"]
    assert [transitions[str(i)]["t_s"] for i in range(len(transitions))] == [t["t_s"] for t in row["transitions"]]
    results = json.loads(reader.results_text)
    assert results["kind"] == "run" and results["row"] == row
    assert results["code"]["source_digest"] and f'id="version-source-digest">{results["code"]["source_digest"]}' in text


def test_run_report_escapes_the_scenario(tmp_path):
    data = minimal_scenario_dict() | {"name": NASTY, "description": NASTY}
    data["sim"]["duration_s"] = 1.0
    file = tmp_path / "nasty.yaml"
    file.write_text(yaml.safe_dump(data))
    out = tmp_path / "nasty.html"
    assert invoke("report", file, "--out", out).exit_code == 0
    text = out.read_text(encoding="utf-8")
    assert NASTY not in text and "<b>bold" not in text
    assert "&lt;script&gt;alert(&quot;x&quot;)&lt;/script&gt; &amp; &lt;b&gt;bold&lt;/b&gt;" in text
    assert text.count("<script") == text.count("</script>")
    assert json.loads(read_report(text).results_text)["row"]["scenario"] == NASTY


# ----------------------------------------------------------------------------------------------- sweep report


def test_sweep_report_tables_equal_the_chunks(tmp_path):
    columns = synthetic_sweep(tmp_path / "sweep")
    out = tmp_path / "sweep.html"
    assert invoke("report", tmp_path / "sweep", "--out", out, "--bins", "4").exit_code == 0
    text = out.read_text(encoding="utf-8")
    assert NASTY not in text and external_references(text) == []
    tables = read_report(text).tables
    collided = columns["collided"]
    overall = tables["overall"]["all"]
    assert (overall["runs"], overall["collisions"]) == (len(collided), int(collided.sum()))
    assert all(same(a, b, 1e-6) for a, b in zip((overall["p_low"], overall["p_high"]),
                                                wilson(int(collided.sum()), len(collided)), strict=True))  # fmt: skip
    speed = columns["ego.cruise_speed_mps"]
    bins = tables["by-0"]
    edges = np.linspace(speed.min(), speed.max(), 5)
    assert len(bins) == 4
    for row in bins.values():
        inside = (speed >= row["bin_low"]) & ((speed < row["bin_high"]) | (row["bin_high"] == speed.max()))
        assert np.isclose(row["bin_high"] - row["bin_low"], edges[1] - edges[0])
        assert (row["runs"], row["collisions"]) == (int(inside.sum()), int(collided[inside].sum()))
        assert same(row["p"], collided[inside].mean())
    by_v2x = {row["value"]: row for row in tables["by-1"].values()}
    for value in (False, True):
        chosen = columns["v2x.enabled"] == value
        assert (by_v2x[value]["runs"], by_v2x[value]["collisions"]) == (int(chosen.sum()), int(collided[chosen].sum()))
        low, high = wilson(int(collided[chosen].sum()), int(chosen.sum()))
        assert same(by_v2x[value]["p_low"], low, 1e-6) and same(by_v2x[value]["p_high"], high, 1e-6)
    assert same(tables["metrics"]["min_ttc_s"]["mean"], columns["min_ttc_s"].mean())


# ----------------------------------------------------------------------------------------------- errors


def _leftovers(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir())


@pytest.mark.parametrize(
    ("args", "names"),
    [
        (["report", "{tmp}/missing.yaml", "--out", "{tmp}/r.html"], ["SOURCE", "missing.yaml", "not found"]),
        (["report", "{tmp}", "--out", "{tmp}/r.html"], ["SOURCE", "manifest.json", "results.parquet"]),
        (["report", "{tmp}/notes.txt", "--out", "{tmp}/r.html"], ["SOURCE", "notes.txt", ".yaml"]),
        (["report", "paper", "--out", "{tmp}/r.pdf"], ["--out", ".html"]),
        (["report", "paper", "--out", "{tmp}/no/such/r.html"], ["--out", "does not exist"]),
        (["report", "paper", "--out", "{tmp}/notes.txt/r.html"], ["--out", "does not exist"]),
        (["report", "paper", "--out", "{tmp}/folder.html"], ["--out", "is a folder"]),
        (["report", "paper", "--out", "{tmp}/r.html", "--v2x", "on"], ["--v2x", "scenario file"]),
        (["report", "CPNCO", "--out", "{tmp}/r.html"], ["SOURCE", "selects 36 catalogue tests"]),
        (["report", "CPNX-50/10kph/day", "--out", "{tmp}/r.html"], ["SOURCE", "did you mean CPNCO-50/10kph/day"]),
        (["report", "{tmp}/bad.yaml", "--out", "{tmp}/r.html"], ["bad.yaml", "ego"]),
        (["paper", "--report", "{tmp}/r.txt"], ["--report", ".html"]),
        (
            ["ncap", "--protocol", "2023", "--scenario", "CPNA-25", "--report", "{tmp}/no/r.html"],
            ["--report", "does not exist"],
        ),
        (["ncap", "--scenario", "NOPE", "--report", "{tmp}/r.html"], ["--scenario"]),
    ],
)
def test_bad_input_exits_2_and_writes_nothing(tmp_path, args, names):
    (tmp_path / "notes.txt").write_text("not a scenario")
    (tmp_path / "folder.html").mkdir()
    (tmp_path / "bad.yaml").write_text("name: x\n")
    before = _leftovers(tmp_path)
    assert_user_error(invoke(*(a.replace("{tmp}", str(tmp_path)) for a in args)), *names)
    assert _leftovers(tmp_path) == before


def test_run_report_of_a_catalogue_test_id(tmp_path):
    """A Euro NCAP test id reports like a scenario file; its row is the one `vrusim run TEST-ID` prints."""
    out = tmp_path / "r.html"
    result = invoke("report", "CPNCO-50/30kph/day", "--v2x", "on", "--out", out)
    assert result.exit_code == 0, result.output
    results = json.loads(read_report(out.read_text(encoding="utf-8")).results_text)
    row = json.loads(invoke("run", "CPNCO-50/30kph/day", "--v2x", "on", "--json").stdout)
    assert results["kind"] == "run" and results["source"] == "CPNCO-50/30kph/day" and results["row"] == row


def test_a_failed_build_keeps_the_old_report(tmp_path):
    out = tmp_path / "r.html"
    out.write_text("old")
    (tmp_path / "bad.yaml").write_text("name: x\n")
    assert_user_error(invoke("report", tmp_path / "bad.yaml", "--out", out), "bad.yaml")
    assert out.read_text() == "old" and _leftovers(tmp_path) == ["bad.yaml", "r.html"]


def test_run_report_of_an_openscenario_file(tmp_path):
    """A .xosc SOURCE is a scenario like a YAML file: the report holds the same numbers as `vrusim run`."""
    source = REPO_ROOT / "tests" / "data" / "xosc" / "roads" / "junction.xosc"
    out = tmp_path / "r.html"
    result = invoke("report", source, "--out", out)
    assert result.exit_code == 0, result.output
    results = json.loads(read_report(out.read_text(encoding="utf-8")).results_text)
    row = json.loads(invoke("run", source, "--json").stdout)
    assert results["kind"] == "run" and results["row"] == row
