"""Issue 17's metrics reach every output: `vrusim run --json`, a sweep's Parquet files, `vrusim summarize`, the
HTML run report and the Gym `info`; never as NaN."""

from __future__ import annotations

import json
import math

import pyarrow as pa
import yaml

from cli_helpers import invoke
from conftest import PAPER_DIR
from vrusim.gym.env import VruEnv
from vrusim.metrics.catalog import get_metric
from vrusim.sweep.runner import run_sweep
from vrusim.sweep.spec import load_spec
from vrusim.sweep.store import SweepStore
from vrusim.sweep.summarize import summarize

PEDESTRIAN = PAPER_DIR / "pedestrian_crossing.yaml"
SCALARS = (
    "speed_reduction_mps", "delta_v_ego_mps", "delta_v_vru_mps", "fatality_risk", "serious_injury_risk",
    "min_clearance_time_s", "min_ttc_time_s", "min_lateral_clearance_m", "min_lateral_clearance_time_s", "tet_s",
    "tit_s2", "peak_drac_mps2", "peak_drac_time_s", "peak_btn", "pet_s",
)  # fmt: skip
PER_VRU = {"min_ttc_per_vru_s": "min_ttc_vru0_s", "min_clearance_per_vru_m": "min_clearance_vru0_m"}


def _no_nan(value) -> bool:
    return not (isinstance(value, float) and math.isnan(value))


def test_run_json_has_every_new_metric_and_no_nan():
    result = invoke("run", PEDESTRIAN, "--v2x", "off", "--json")
    assert result.exit_code == 0, result.output
    row = json.loads(result.stdout)
    for name in SCALARS:
        assert name in row and _no_nan(row[name]), name
    assert row["fatality_risk"] > 0 and row["delta_v_vru_mps"] > row["delta_v_ego_mps"] > 0
    assert row["min_ttc_per_vru_s"] == [row["min_ttc_s"]]
    assert row["min_clearance_per_vru_m"] == [row["min_clearance_m"]]
    assert "NaN" not in result.stdout


def test_sweep_parquet_and_summarize_have_the_new_metrics(tmp_path):
    spec = {
        "name": "surrogates",
        "base": str(PEDESTRIAN),
        "set": {"sim.duration_s": 6.0, "metrics.tet_ttc_threshold_s": 2.0},
        "parameters": {"ego.cruise_speed_mps": [8.0, 14.0], "vrus[0].mass_kg": [60.0, 90.0]},
        "batch_size": 2,
    }
    (tmp_path / "spec.yaml").write_text(yaml.safe_dump(spec))
    run_sweep(load_spec(tmp_path / "spec.yaml"), tmp_path / "out", workers=1)
    table = SweepStore(tmp_path / "out").read()
    for name in (*SCALARS, *PER_VRU.values()):
        assert table.schema.field(name).type == pa.float64(), name
    summary = summarize(tmp_path / "out", metrics=["fatality_risk", "tet_s", "pet_s", "min_ttc_vru0_s"])
    assert summary["metrics"] == ["fatality_risk", "tet_s", "pet_s", "min_ttc_vru0_s"]
    assert 0.0 <= summary["overall"]["metrics"]["fatality_risk"]["max"] <= 1.0
    result = invoke("summarize", tmp_path / "out", "--metrics", "delta_v_vru_mps,peak_btn", "--json")
    assert result.exit_code == 0, result.output
    assert set(json.loads(result.stdout)["metrics"]) == {"delta_v_vru_mps", "peak_btn"}


def test_html_run_report_shows_the_new_metrics(tmp_path):
    out = tmp_path / "run.html"
    result = invoke("report", PEDESTRIAN, "--out", out)
    assert result.exit_code == 0, result.output
    html = out.read_text(encoding="utf-8")
    for name in SCALARS:
        assert f'data-row="{name}"' in html, name
    assert 'id="per-vru"' in html
    for name in PER_VRU:
        assert get_metric(name).label in html


def test_gym_info_has_the_new_metrics():
    env = VruEnv("paper:pedestrian", v2x=False)
    env.reset(seed=0)
    info: dict = {}
    while "metrics" not in info:
        *_, info = env.step([0.0])
    for name in (*SCALARS, *PER_VRU.values()):
        assert name in info["metrics"], name
    metrics = info["metrics"]  # holding its speed, the ego passes the pedestrian closely (issue 17)
    assert not metrics["collided"] and metrics["fatality_risk"] == 0.0
    assert metrics["min_clearance_vru0_m"] == metrics["min_clearance_m"] < 1.0
