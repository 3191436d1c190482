"""The metric catalogue: each metric declared once, and the result columns, summary rows, Arrow types, terminal
summary, report table and docs derived from it; a plug-in metric registered from a test-only module
(`extra_metric.py`) appears in all of them and is gone again after the test."""

from __future__ import annotations

import json
import re

import numpy as np
import pyarrow as pa
import pytest
import yaml

import extra_metric
from cli_helpers import invoke
from conftest import PAPER_DIR, REPO_ROOT
from vrusim.engine.accumulators import ACCUMULATORS, FIELDS, REDUCTIONS
from vrusim.engine.simulate import simulate
from vrusim.metrics import catalog
from vrusim.metrics.catalog import (
    IDENTITY_KEYS,
    METRIC_REDUCTIONS,
    Metric,
    from_accumulator,
    get_metric,
    metrics,
    register_metric,
    unregister_metric,
)
from vrusim.metrics.columns import FLOAT_COLUMNS, SCORE_COLUMNS, result_columns
from vrusim.metrics.display import DisplayRow, display_rows
from vrusim.metrics.summary import summary_rows
from vrusim.report.parts import scalar_fields, summary_table
from vrusim.scenario.loading import load_scenario
from vrusim.sweep.runner import run_sweep
from vrusim.sweep.spec import load_spec
from vrusim.sweep.store import SweepStore
from vrusim.sweep.tables import chunk_table, result_type
from vrusim.viz.sensitivity import unit_of

PEDESTRIAN = PAPER_DIR / "pedestrian_crossing.yaml"

SUMMARY_KEYS = [
    "scenario",
    "v2x",
    "planner",
    "outcome",
    "collided",
    "contact_time_s",
    "impact_ego_speed_mps",
    "impact_relative_speed_mps",
    "impact_relative_longitudinal_speed_mps",
    "impact_point_x_m",
    "impact_point_y_m",
    "impact_side",
    "impact_lateral_fraction",
    "impact_body_side",
    "impact_location",
    "door_collision",
    "impact_vru",
    "speed_reduction_mps",
    "delta_v_ego_mps",
    "delta_v_vru_mps",
    "fatality_risk",
    "serious_injury_risk",
    "first_sensor_detection_s",
    "first_v2x_message_s",
    "first_warning_s",
    "warning_ttc_s",
    "first_mode_s",
    "transitions",
    "min_clearance_m",
    "min_clearance_time_s",
    "min_ttc_s",
    "min_ttc_time_s",
    "min_lateral_clearance_m",
    "min_lateral_clearance_time_s",
    "tet_s",
    "tit_s2",
    "peak_drac_mps2",
    "peak_drac_time_s",
    "peak_btn",
    "pet_s",
    "min_ttc_per_vru_s",
    "min_clearance_per_vru_m",
    "peak_accel_mps2",
    "peak_decel_mps2",
    "peak_jerk_mps3",
    "peak_lateral_accel_mps2",
    "rms_accel_mps2",
    "rms_jerk_mps3",
    "moving_time_s",
    "travel_time_s",
    "trip_time_s",
    "free_travel_time_s",
    "end_time_s",
    "final_speed_mps",
    "safety",
    "efficiency",
    "comfort",
    "score_profile",
]
"""The summary row's keys in order, as before the catalogue (JSON of `vrusim run --json`), with issue 17's metrics."""
PER_VRU_COLUMNS = {"min_ttc_per_vru_s": ["min_ttc_vru0_s"], "min_clearance_per_vru_m": ["min_clearance_vru0_m"]}
"""The per-VRU metrics and their columns in a batch with one VRU slot."""
MEASURES = [
    key
    for key in SUMMARY_KEYS[SUMMARY_KEYS.index("contact_time_s") : SUMMARY_KEYS.index("safety")]
    if key not in ("impact_side", "impact_body_side", "door_collision", "impact_vru", "first_mode_s", "transitions")
]
FLOATS = [key for key in MEASURES if key not in PER_VRU_COLUMNS]
"""The float measure columns: the metrics of the summary row but the outcome columns, planner ones, scores and the
per-VRU metrics (several columns each)."""
FSM_COLUMNS = [
    *("outcome", "collided", "impact_side", "impact_body_side", "door_collision", "impact_vru"),
    *(column for key in MEASURES for column in PER_VRU_COLUMNS.get(key, [key])),
    *("first_pre_slow_s", "first_emergency_brake_s", "first_follow_s", "transitions"),
    *("safety", "efficiency", "comfort"),
]
"""The result columns of an FSM batch in order, as before the catalogue (the sweep's Parquet columns)."""
CLI_LABELS = [
    "Outcome",
    "Contact time",
    "Impact ego speed",
    "Impact relative speed",
    "Impact side",
    "First sensor detection",
    "First V2X message",
    "Planner transitions",
    "Min TTC",
    "Min clearance",
    "Peak accel / decel",
    "Peak jerk",
    "RMS accel",
    "RMS jerk",
    "Travel time",
    "Min lateral clearance",
    "PET",
    "Peak DRAC",
    "TET / TIT",
    "Min TTC per VRU",
    "Min clearance per VRU",
    "Speed reduction before impact",
    "Δv ego / VRU",
    "Fatality / serious injury risk",
    "Safety score",
    "Efficiency score",
    "Comfort score",
]
"""The labels of `vrusim run`'s terminal table before the catalogue (hand-written in cli/main.py)."""
SECTION_ENDS = {"Outcome", "Impact side", "Planner transitions", "Travel time", "Fatality / serious injury risk"}


@pytest.fixture(scope="module")
def run():
    """The paper's pedestrian case, V2X off (collision) and on (avoided), as one FSM batch with a trace."""
    scenario = load_scenario(PEDESTRIAN)
    return simulate([scenario.with_v2x(False), scenario.with_v2x(True)], trace=True)


@pytest.fixture
def plugin():
    """The metrics of `extra_metric.py` registered for one test, and removed again after it."""
    extra_metric.register()
    try:
        yield extra_metric.METRICS
    finally:
        extra_metric.unregister()
    assert not {m.name for m in extra_metric.METRICS} & {m.name for m in metrics()}


# ----------------------------------------------------------------------------------------------- the catalogue


def test_rows_and_columns_keep_their_names_and_order(run):
    rows = summary_rows(run)
    assert [list(row) for row in rows] == [SUMMARY_KEYS, SUMMARY_KEYS]
    assert run.mode_names == ("cruise", "pre_slow", "emergency_brake", "follow")
    columns = result_columns(run)
    assert list(columns) == FSM_COLUMNS
    assert list(FLOAT_COLUMNS) == FLOATS
    assert SCORE_COLUMNS == ("safety", "efficiency", "comfort")
    assert [row["outcome"] for row in rows] == ["collision", "avoided"]
    assert isinstance(rows[0]["impact_vru"], int) and rows[1]["impact_vru"] is None
    assert rows[0]["transitions"] and columns["transitions"][0] == len(rows[0]["transitions"])


def test_column_types_follow_the_declared_dtypes(run):
    columns = result_columns(run)
    for name, values in columns.items():
        kind = catalog.column_dtype(name)
        assert {"float64": "f", "int64": "i", "bool": "b", "string": "O"}[kind] == values.dtype.kind, name
    expected = {"outcome": pa.string(), "collided": pa.bool_(), "impact_side": pa.string(), "transitions": pa.int64()}
    expected.update(impact_body_side=pa.string(), door_collision=pa.bool_())
    for name in FSM_COLUMNS:
        assert result_type(name) == expected.get(name, pa.float64()), name
    table = chunk_table({"variant": [0, 1]}, {"variant": pa.int64()}, columns)
    assert table.column_names == ["variant", *FSM_COLUMNS]


def test_every_metric_is_declared_consistently():
    names = [m.name for m in metrics()]
    assert len(names) == len(set(names))
    assert not set(names) & set(IDENTITY_KEYS)
    for metric in metrics():
        assert metric.reduce in METRIC_REDUCTIONS and metric.label and metric.doc, metric.name
        assert metric.source.startswith("docs/metrics.md#"), metric.name
        if metric.group != "score":  # the unit is the name's suffix, as figures and reports read it
            assert (unit_of(metric.name) or "") == metric.unit, metric.name
        if metric.accumulator:  # a metric that is an accumulator row reduces as the row does
            assert metric.reduce == dict((a.name, a.reduce) for a in ACCUMULATORS)[metric.accumulator]


def test_accumulator_rows_are_declared_with_their_reductions():
    assert len(FIELDS) == len(set(FIELDS)) == len(ACCUMULATORS)
    assert all(row.reduce in REDUCTIONS and row.doc for row in ACCUMULATORS)
    used = {m.accumulator for m in metrics() if m.accumulator}
    assert used <= set(FIELDS)
    assert not any(row.reduce == "carry" for row in ACCUMULATORS if row.name in used)


def _slug(heading: str) -> str:
    return re.sub(r"[^\w\- ]", "", heading.strip().lower()).replace(" ", "-")


def test_docs_table_lists_the_catalogue():
    """docs/metrics.md's table is the catalogue: the same metrics, in order, with unit, label, dtype, group,
    reduction and the section that defines each (which exists)."""
    text = (REPO_ROOT / "docs" / "metrics.md").read_text(encoding="utf-8")
    anchors = {_slug(line.lstrip("#")) for line in text.splitlines() if line.startswith("## ")}
    lines = text.splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("| Metric (column, JSON key) |")) + 2
    rows = [line for line in lines[start:] if line.startswith("|")]
    rows = rows[: next((i for i, line in enumerate(lines[start:]) if not line.startswith("|")), len(rows))]
    documented = []
    for line in rows:
        name, unit, label, dtype, group, reduce, link = (cell.strip() for cell in line.strip("|").split("|"))
        anchor = re.fullmatch(r"\[[^\]]+\]\(#([\w-]+)\)", link).group(1)
        assert anchor in anchors, (name, anchor)
        documented.append((name.strip("`"), "" if unit == "—" else unit, label, dtype, group, reduce, anchor))
    declared = [
        (m.name, m.unit, m.label, m.dtype, m.group, m.reduce, m.source.split("#")[1])
        for m in metrics()
        if catalog.is_builtin(m.name)
    ]
    assert documented == declared


def test_report_summary_table_takes_labels_and_units_from_the_catalogue(run):
    row = summary_rows(run)[0]
    html = str(summary_table("summary", row))
    fields = scalar_fields(row)
    assert fields[:3] == ["outcome", "collided", "contact_time_s"]
    assert fields[-4:] == ["scenario", "v2x", "planner", "score_profile"]
    for name in ("min_ttc_s", "peak_lateral_accel_mps2", "impact_point_x_m", "safety"):
        assert get_metric(name).label in html
    assert "m/s²" in html


# ----------------------------------------------------------------------------------------------- terminal summary


def _row(**values) -> dict:
    """A summary row whose every field is absent unless given."""
    row = dict.fromkeys(SUMMARY_KEYS)
    row.update(collided=False, transitions=[], first_mode_s={})
    row.update(values)
    return row


def test_display_rows_reproduce_the_terminal_table():
    collision = _row(
        collided=True,
        contact_time_s=2.5,
        impact_ego_speed_mps=8.25,
        impact_relative_speed_mps=8.5,
        impact_relative_longitudinal_speed_mps=8.0,
        impact_side="front",
        impact_lateral_fraction=0.5,
        first_sensor_detection_s=1.0,
        transitions=[{"t_s": 1.25, "from": "cruise", "to": "[bold]emergency_brake"}],
        min_ttc_s=0.0,
        min_clearance_m=-0.25,
        peak_accel_mps2=0.5,
        peak_decel_mps2=6.0,
        peak_jerk_mps3=12.5,
        rms_accel_mps2=2.0,
        rms_jerk_mps3=3.0,
        trip_time_s=9.5,
        free_travel_time_s=7.25,
        pet_s=0.0,
        peak_drac_mps2=12.5,
        peak_btn=1.5625,
        peak_drac_time_s=2.4,
        tet_s=1.25,
        tit_s2=0.75,
        min_ttc_per_vru_s=[0.0],
        min_clearance_per_vru_m=[-0.25],
        speed_reduction_mps=1.75,
        delta_v_ego_mps=0.5,
        delta_v_vru_mps=8.0,
        fatality_risk=0.02,
        serious_injury_risk=0.1,
        safety=0.0,
        efficiency=0.0,
        comfort=0.0,
    )
    texts = [
        "[bold red]COLLISION[/]",
        "2.50 s",
        "8.25 m/s",
        "8.50 m/s (longitudinal 8.00 m/s)",
        "front, lateral fraction 0.50",
        "1.00 s",
        "—",
        "1.25 s  cruise → \\[bold]emergency_brake",
        "0.00 s",
        "-0.25 m",
        "0.50 / 6.00 m/s²",
        "12.50 m/s³",
        "2.00 m/s²",
        "3.00 m/s³",
        "route not completed (trip time counted as 9.50 s, free flow 7.25 s)",
        "—",
        "0.00 s",
        "12.50 m/s² (BTN 1.56) at 2.40 s",
        "1.25 s / 0.75 s²",
        "#0 0.00 s",
        "#0 -0.25 m",
        "1.75 m/s",
        "0.50 m/s / 8.00 m/s",
        "0.02 / 0.10",
        "0.00",
        "0.00",
        "0.00",
    ]
    expected = [DisplayRow(label, text, label in SECTION_ENDS) for label, text in zip(CLI_LABELS, texts, strict=True)]
    assert display_rows(collision) == expected
    avoided = _row(travel_time_s=7.5, free_travel_time_s=7.25, safety=1.0, efficiency=0.75, comfort=0.5)
    lines = {line.label: line.text for line in display_rows(avoided)}
    assert lines["Outcome"] == "[bold green]avoided[/]"
    assert lines["Impact relative speed"] == lines["Impact side"] == lines["Contact time"] == "—"
    assert lines["Planner transitions"] == "none"
    assert lines["Travel time"] == "7.50 s (free flow 7.25 s)"
    assert lines["Efficiency score"] == "0.75"


def test_display_rows_equal_the_cli_table(run):
    """Same labels, texts and section rules as the table `vrusim run` prints, for real rows."""
    from vrusim.cli.run import _summary_table

    for row in summary_rows(run):
        table = _summary_table(row)
        labels, texts = (column._cells for column in table.columns)
        assert [line.label for line in display_rows(row)] == labels == CLI_LABELS
        assert [line.text for line in display_rows(row)] == texts
        assert [line.end_section for line in display_rows(row)] == [r.end_section for r in table.rows]


# ----------------------------------------------------------------------------------------------- plug-in metrics


def test_a_plugin_metric_is_in_summary_rows_and_columns(run, plugin):
    rows = summary_rows(run)
    assert list(rows[0]) == [*SUMMARY_KEYS[:-1], "mean_speed_mps", "stopped_at_end", "score_profile"]
    columns = result_columns(run)
    at = FSM_COLUMNS.index("final_speed_mps") + 1  # measures come before the planner's columns
    assert list(columns) == [*FSM_COLUMNS[:at], "mean_speed_mps", "stopped_at_end", *FSM_COLUMNS[at:]]
    assert columns["stopped_at_end"].dtype == bool
    trace = run.trace
    for b, row in enumerate(rows):  # distance along the route over the active time, from the trace
        last = int(np.argmin(np.abs(trace["t_s"] - row["end_time_s"])))
        assert row["mean_speed_mps"] == pytest.approx(trace["ego_station_m"][last, b] / row["end_time_s"], rel=1e-6)
        assert row["stopped_at_end"] is (row["final_speed_mps"] == 0.0)
    assert 0 < rows[0]["mean_speed_mps"] < load_scenario(PEDESTRIAN).ego.cruise_speed_mps


def test_a_plugin_metric_is_in_arrow_tables_and_a_sweeps_parquet_file(run, plugin, tmp_path):
    table = chunk_table({"variant": [0, 1]}, {"variant": pa.int64()}, result_columns(run))
    assert table.schema.field("mean_speed_mps").type == pa.float64()
    assert table.schema.field("stopped_at_end").type == pa.bool_()
    spec = {
        "name": "plugin-metric",
        "base": str(PEDESTRIAN),
        "set": {"sim.duration_s": 4.0},
        "parameters": {"ego.cruise_speed_mps": [10.0, 14.0]},
        "batch_size": 2,
    }
    (tmp_path / "spec.yaml").write_text(yaml.safe_dump(spec))
    run_sweep(load_spec(tmp_path / "spec.yaml"), tmp_path / "out", workers=1)  # in this process
    results = SweepStore(tmp_path / "out").read()
    assert results.schema.field("mean_speed_mps").type == pa.float64()
    assert results.schema.field("stopped_at_end").type == pa.bool_()
    assert all(v > 0 for v in results.column("mean_speed_mps").to_pylist())


def test_a_plugin_metric_is_in_the_cli_json_and_the_terminal_summary(plugin):
    result = invoke("run", PEDESTRIAN, "--v2x", "off", "--json")
    assert result.exit_code == 0, result.output
    row = json.loads(result.stdout)
    assert row["mean_speed_mps"] > 0 and isinstance(row["stopped_at_end"], bool)
    lines = display_rows(row)
    assert [line.label for line in lines] == [*CLI_LABELS, "Mean speed", "Stopped at the end"]
    assert lines[-2].text == f"{row['mean_speed_mps']:.2f} m/s" and lines[-1].text in ("yes", "no")
    assert lines[len(CLI_LABELS) - 1].end_section and not lines[-1].end_section


def test_a_metric_can_be_placed_and_is_removed_again(run):
    metric = Metric("ttc_margin_s", "s", "TTC margin", "min TTC - 1 s", lambda view: view["min_ttc_s"] - 1.0)
    register_metric(metric, after="min_ttc_s")
    try:
        keys = list(summary_rows(run)[1])
        assert keys[keys.index("min_ttc_s") + 1] == "ttc_margin_s"
        columns = list(result_columns(run))
        assert columns[columns.index("min_ttc_s") + 1] == "ttc_margin_s"
    finally:
        assert unregister_metric("ttc_margin_s") is metric
    assert list(summary_rows(run)[1]) == SUMMARY_KEYS
    assert list(result_columns(run)) == FSM_COLUMNS


def _metric(name: str = "spare_s", **changes) -> Metric:
    fields = {"unit": "s", "label": "Spare", "doc": "nothing", "compute": lambda view: np.zeros(view.size)}
    return Metric(name, **{**fields, **changes})


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (lambda: _metric("min_ttc_s"), "already declared"),
        (lambda: _metric("scenario"), "what ran"),
        (lambda: _metric("Spare"), "snake_case"),
        (lambda: _metric(dtype="float32"), "dtype"),
        (lambda: _metric(group="extra"), "group"),
        (lambda: _metric(reduce="median"), "reduce"),
        (lambda: _metric(reduce="carry"), "reduce"),
        (lambda: _metric(label=""), "label"),
    ],
)
def test_bad_metric_declarations_are_refused(make, message):
    with pytest.raises(ValueError, match=message):
        register_metric(make())
    assert "spare_s" not in {m.name for m in metrics()}


def test_declaration_errors_name_the_culprit(run):
    with pytest.raises(KeyError, match="no accumulator row 'mean_speed'"):
        from_accumulator("mean_speed_mps", "m/s", "Mean speed", "nothing", row="mean_speed")
    with pytest.raises(KeyError, match="no metric 'nowhere'"):
        register_metric(_metric(), after="nowhere")
    with pytest.raises(ValueError, match="built in"):
        unregister_metric("min_ttc_s")
    register_metric(Metric("bad_shape_s", "s", "Bad", "nothing", lambda view: np.zeros((view.size, 2))))
    try:
        with pytest.raises(ValueError, match=r"bad_shape_s.*shape \(2, 2\)"):
            result_columns(run)
    finally:
        unregister_metric("bad_shape_s")
