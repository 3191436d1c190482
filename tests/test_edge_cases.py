"""Edge cases found in review: curved-route projection, padding independence, non-finite input, planner output,
coarse time steps, free-flow travel time, large per-step turns."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from vrusim.engine.simulate import simulate
from vrusim.errors import UserInputError
from vrusim.metrics.summary import summary_rows
from vrusim.planners.base import HoldSpeedPlanner
from vrusim.planners.registry import make_planner
from vrusim.scenario.loading import scenario_from_mapping
from vrusim.sim.ego import rotate

FAST_MOTO = {
    "type": "motorcyclist",
    "start": [31.0, -30.0],
    "heading_deg": 90.0,
    "radius_m": 0.3,
    "top_speed_mps": 30.0,
    "max_accel_mps2": 1000.0,
    "trigger": {"at_time_s": 0.0},
}
"""A 30 m/s motorcyclist crossing 31 m ahead of the ego's start: it meets a 30 m/s ego after about 1 s."""


def _u_turn(make_scenario, vrus, **sim):
    return make_scenario(
        {
            "ego": {
                "cruise_speed_mps": 10.0,
                "route": {
                    "kind": "left",
                    "turn_at_m": 10.0,
                    "radius_m": 10.0,
                    "angle_deg": 180.0,
                    "length_m": 10.0 + 10.0 * math.pi,
                },
            },
            "planner": {"name": "fsm"},
            "vrus": vrus,
            "sim": {"duration_s": 15.0, "stop_at_route_end": False, **sim},
        }
    )


def test_fsm_brakes_for_a_vru_first_seen_on_the_far_leg_of_a_u_turn(make_scenario):
    """The track is projected globally when first acquired: a local warm start would pick the wrong leg."""
    cyclist = {"type": "cyclist", "start": [-10.0, -5.0], "path": [[-30.0, 19.0]], "trigger": {"at_time_s": 1.0}}
    row = summary_rows(simulate([_u_turn(make_scenario, [cyclist])]))[0]
    assert row["first_sensor_detection_s"] is not None
    assert row["first_mode_s"]["emergency_brake"] == pytest.approx(row["first_sensor_detection_s"])
    assert row["outcome"] == "avoided"


def test_vru_beyond_the_route_end_is_seen_on_the_extension_alone_and_in_any_batch(make_scenario):
    """Projection searches a path's own samples and its straight extensions, never the table padding."""
    standing = {"type": "pedestrian", "start": [-40.0, 20.0], "heading_deg": 90.0, "trigger": {"at_time_s": 1e3}}
    u_turn = _u_turn(make_scenario, [standing])
    long_straight = make_scenario({"ego": {"route": {"length_m": 400.0}}, "planner": {"name": "fsm"}})
    alone = summary_rows(simulate([u_turn]))[0]
    in_batch = summary_rows(simulate([u_turn, long_straight]))[0]
    assert alone == in_batch
    assert alone["outcome"] == "avoided"


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("ego.cruise_speed_mps", math.inf),
        ("ego.start.x_m", math.nan),
        ("vrus[0].heading_deg", math.inf),
        ("ego.route.length_m", math.inf),
        ("v2x.rsu.x_m", math.nan),
    ],
)
def test_non_finite_numbers_are_rejected_naming_the_field(scenario_dict, field, value):
    target = scenario_dict
    scenario_dict["v2x"] = {"rsu": {"x_m": 0.0, "y_m": 5.0}}
    parts = field.replace("[0]", ".0").split(".")
    for part in parts[:-1]:
        target = target[int(part)] if part.isdigit() else target[part]
    target[parts[-1]] = value
    with pytest.raises(UserInputError, match=re.escape(field) + ": .*finite"):
        scenario_from_mapping(scenario_dict)


def test_fsm_parameters_must_be_finite(make_scenario):
    scenario = make_scenario({"planner": {"name": "fsm", "params": {"track_memory_s": math.inf}}})
    with pytest.raises(UserInputError, match=r"planner\.params\.track_memory_s"):
        simulate([scenario])


def test_route_tighter_than_the_steering_allows_is_rejected(scenario_dict):
    scenario_dict["ego"]["route"] = {"kind": "left", "turn_at_m": 5.0, "radius_m": 2.0, "length_m": 50.0}
    with pytest.raises(UserInputError, match=r"ego: .*route\.radius_m 2\.0 m is tighter"):
        scenario_from_mapping(scenario_dict)


class _ShortCommand(HoldSpeedPlanner):
    def act(self, observation):
        return np.array([-6.0])


class _NanCommand(HoldSpeedPlanner):
    def act(self, observation):
        return np.full(observation.ego_speed_mps.shape, np.nan)


class _MutatingPlanner(HoldSpeedPlanner):
    def act(self, observation):
        observation.ego_speed_mps *= 0.5
        return np.zeros(observation.ego_speed_mps.shape)


@pytest.mark.parametrize("planner", [_ShortCommand(), _NanCommand()], ids=["wrong-shape", "nan"])
def test_bad_planner_output_is_one_clear_error(make_scenario, planner):
    with pytest.raises(UserInputError, match=r"must return a finite acceleration per variant, shape \(3,\)"):
        simulate([make_scenario()] * 3, planner=planner)


def test_planner_cannot_change_the_state_it_observes(make_scenario):
    with pytest.raises(ValueError, match="read-only"):
        simulate([make_scenario()], planner=_MutatingPlanner())


@pytest.mark.parametrize("name", ["os:path", ":", "vrusim.engine.simulate:BatchRun"])
def test_broken_plugin_names_are_user_errors(name):
    with pytest.raises(UserInputError, match=r"planner\.name"):
        make_planner(name)


@pytest.mark.parametrize("dt", [0.001, 0.01, 0.05, 0.1])
def test_fast_crossing_collides_whatever_the_time_step(make_scenario, dt):
    """A 30 m/s motorcyclist crossing a 30 m/s ego is caught by the swept test even when it would pass through
    the ego between two step ends."""
    scenario = make_scenario({"ego": {"cruise_speed_mps": 30.0}, "vrus": [FAST_MOTO], "sim": {"dt_s": dt}})
    row = summary_rows(simulate([scenario]))[0]
    assert row["outcome"] == "collision"
    # the moto's edge reaches the ego's right side after (30 - 0.9 - 0.3) m at 30 m/s, 0.015 s lost accelerating
    assert row["contact_time_s"] == pytest.approx((30.0 - 0.9 - 0.3) / 30.0 + 0.015, abs=dt + 0.01)


@pytest.mark.parametrize("dt", [0.01, 0.03, 0.1])
def test_free_flow_trip_takes_length_over_speed_and_scores_efficiency_one(make_scenario, dt):
    row = summary_rows(
        simulate([make_scenario({"ego": {"route": {"length_m": 73.0}}, "sim": {"dt_s": dt, "duration_s": 20}})])
    )[0]
    assert row["travel_time_s"] == pytest.approx(7.3, abs=1e-6)
    assert row["efficiency"] == 1.0


def test_an_ego_told_to_stand_still_loses_no_time(make_scenario):
    row = summary_rows(simulate([make_scenario({"ego": {"cruise_speed_mps": 0.0}})]))[0]
    assert row["efficiency"] == 1.0


@pytest.mark.parametrize("angle", [0.0, 1e-4, 0.049, 0.051, 0.3, 1.0, 2.5, -1.7])
def test_rotation_is_exact_for_small_and_large_angles(angle):
    x, y = rotate(0.6, 0.8, angle)
    assert x == pytest.approx(0.6 * math.cos(angle) - 0.8 * math.sin(angle), abs=1e-10)
    assert y == pytest.approx(0.6 * math.sin(angle) + 0.8 * math.cos(angle), abs=1e-10)


def test_swept_contact_reports_the_side_that_was_hit(make_scenario):
    """At a coarse step a fast VRU crossing from the right passes through the ego between two step ends: the
    impact is still on the right side, and the minimum clearance records the contact."""
    scenario = make_scenario({"ego": {"cruise_speed_mps": 30.0}, "vrus": [FAST_MOTO], "sim": {"dt_s": 0.1}})
    row = summary_rows(simulate([scenario]))[0]
    assert row["outcome"] == "collision"
    assert row["impact_side"] == "right"
    assert row["min_clearance_m"] <= 0.0


def test_kernel_caches_of_old_source_versions_are_pruned(tmp_path):
    """Each source version compiles into its own cache folder; folders unused for a week are deleted."""
    import os
    import time

    from vrusim.kernels import prune_kernel_caches

    old, recent, current = (tmp_path / name for name in ("old", "recent", "current"))
    for folder in (old, recent, current):
        folder.mkdir()
        (folder / "kernel.nbi").write_text("x")
    week_ago = time.time() - 8 * 86400
    os.utime(old, (week_ago, week_ago))
    os.utime(current, (week_ago, week_ago))
    prune_kernel_caches(tmp_path, keep="current", unused_days=7)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["current", "recent"]
    assert time.time() - current.stat().st_mtime < 60  # using a folder marks it as recent


def test_gc_paused_restores_the_collector_state_and_nests():
    """Sweep batches pause the cyclic collector; only the outermost block turns it back on."""
    import gc

    from vrusim.sweep.gc_pause import gc_paused

    assert gc.isenabled()
    with gc_paused():
        assert not gc.isenabled()
        with gc_paused():
            assert not gc.isenabled()
        assert not gc.isenabled()
    assert gc.isenabled()
    gc.disable()
    try:
        with gc_paused():
            pass
        assert not gc.isenabled()  # a caller that had it off keeps it off
    finally:
        gc.enable()
