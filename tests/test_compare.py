"""`vrusim compare`: every planner × V2X combination, Wilson intervals, and user errors."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from typer.testing import CliRunner

from vrusim.cli import app
from vrusim.compare import wilson_interval

PEDESTRIAN = Path(__file__).resolve().parents[1] / "scenarios" / "paper" / "pedestrian_crossing.yaml"
runner = CliRunner()


def invoke(*args):
    return runner.invoke(app, [str(a) for a in args], catch_exceptions=False)


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
        (["--v2x", "no-such-profile"], ["v2x.channel"]),
        (["--seeds", "0"], ["--seeds"]),
    ],
)
def test_bad_options_are_user_errors(args, names):
    result = invoke("compare", PEDESTRIAN, *args)
    assert result.exit_code == 2, result.output
    for name in names:
        assert name in result.output
    assert "Traceback" not in result.output
