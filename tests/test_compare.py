"""`vrusim compare`: every planner × V2X combination, Wilson intervals, and user errors."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from cli_helpers import invoke
from vrusim.studies.compare import wilson_interval

PEDESTRIAN = Path(__file__).resolve().parents[1] / "scenarios" / "paper" / "pedestrian_crossing.yaml"


def test_wilson_interval_hand_values():
    # Wilson (1927): 0 of 10 -> [0, 0.2775]; 5 of 10 -> [0.2366, 0.7634]; 10 of 10 -> [0.7225, 1]
    assert wilson_interval(0, 10) == pytest.approx((0.0, 0.27753), abs=1e-4)
    assert wilson_interval(5, 10) == pytest.approx((0.23659, 0.76341), abs=1e-4)
    assert wilson_interval(10, 10) == pytest.approx((0.72247, 1.0), abs=1e-4)


def test_compare_reproduces_the_single_runs():
    """The FSM rows equal `vrusim run` of the paper case with V2X off and on."""
    result = invoke("compare", PEDESTRIAN, "--planners", "fsm,none", "--v2x", "off,ideal", "--json")
    assert result.exit_code == 0, result.output
    rows = {(r["planner"], r["v2x"]): r for r in json.loads(result.stdout)}
    assert set(rows) == {("fsm", "off"), ("fsm", "ideal"), ("none", "off"), ("none", "ideal")}
    for v2x, switch in (("off", "off"), ("ideal", "on")):
        single = json.loads(invoke("run", PEDESTRIAN, "--v2x", switch, "--json").stdout)
        row = rows["fsm", v2x]
        assert row["collisions"] == int(single["collided"])
        assert (row["safety"], row["efficiency"], row["comfort"]) == pytest.approx(
            (single["safety"], single["efficiency"], single["comfort"]), abs=1e-4
        )
    assert rows["none", "off"]["mean_first_v2x_message_s"] is None
    assert not math.isnan(rows["none", "ideal"]["safety"])


@pytest.mark.parametrize(
    ("args", "names"),
    [
        (["--planners", "fsm,bogus"], ["--planners", "bogus"]),
        (["--planners", " , "], ["--planners"]),
        (["--v2x", "no-such-profile"], ["--v2x", "no-such-profile", "typical"]),
        (["--seeds", "0"], ["--seeds"]),
        (  # the last seed, 2^63, named sim.seed
            ["--v2x", "off", "--seeds", "2", "--seed", "9223372036854775807"],
            ["--seed, --seeds:", "give --seed from 0 to 9,223,372,036,854,775,806 with --seeds 2"],
        ),
    ],
)
def test_bad_options_are_user_errors(args, names):
    result = invoke("compare", PEDESTRIAN, *args)
    assert result.exit_code == 2, result.output
    for name in names:
        assert name in result.output
    assert "Traceback" not in result.output


def test_user_profiles_from_a_file_are_compared_by_name(tmp_path):
    """A 1 s latency profile defined in YAML: the first V2X message arrives 1 s after the ideal one."""
    profiles = tmp_path / "profiles.yaml"
    profiles.write_text("slow:\n  generation: {mode: every_step}\n  latency_s: 1.0\n  track_max_age_s: 2.0\n")
    result = invoke("compare", PEDESTRIAN, "--v2x", "ideal,slow", "--profiles", profiles, "--json")
    assert result.exit_code == 0, result.output
    rows = {r["v2x"]: r for r in json.loads(result.stdout)}
    assert rows["slow"]["mean_first_v2x_message_s"] == pytest.approx(rows["ideal"]["mean_first_v2x_message_s"] + 1.0)


def test_a_random_channel_gives_a_distribution_over_seeds():
    result = invoke("compare", PEDESTRIAN, "--v2x", "lossy", "--seeds", "20", "--json")
    assert result.exit_code == 0, result.output
    (row,) = json.loads(result.stdout)
    assert row["runs"] == 20
    low, high = row["collision_probability_95"]
    assert low <= row["collision_probability"] <= high


def test_other_planners_run_with_their_defaults():
    """The paper file's FSM parameters do not apply to other planners: they run with their own defaults."""
    result = invoke("compare", PEDESTRIAN, "--planners", "aeb,predictive", "--v2x", "ideal", "--json")
    assert result.exit_code == 0, result.output
    rows = {r["planner"]: r for r in json.loads(result.stdout)}
    assert rows["aeb"]["collisions"] == rows["predictive"]["collisions"] == 0


def test_compare_takes_a_catalogue_test_id_with_its_roadside_unit():
    """A catalogue test compares like a file; its roadside unit makes the V2X settings possible."""

    result = invoke("compare", "CMRb/80kph/day", "--planners", "fsm,aeb", "--v2x", "off,ideal", "--json")
    assert result.exit_code == 0, result.output
    rows = json.loads(result.stdout)
    assert [(r["planner"], r["v2x"]) for r in rows] == [
        ("fsm", "off"),
        ("fsm", "ideal"),
        ("aeb", "off"),
        ("aeb", "ideal"),
    ]
    assert all(r["collisions"] == 0 for r in rows)
    v2x_message = {r["v2x"]: r["mean_first_v2x_message_s"] for r in rows if r["planner"] == "fsm"}
    assert v2x_message["off"] is None and v2x_message["ideal"] is not None
