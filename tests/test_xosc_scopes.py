"""Parameter scopes (ASAM OpenSCENARIO 1.3, section 9.1): `<ParameterDeclarations>` inside a Story, a Maneuver,
a Trajectory or an inline entity hold in that element's subtree only, and hide an outer parameter of the same
name there."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from vrusim.formats.xosc_import import read_xosc
from xosc_helpers import edited, refused

DATA = Path(__file__).parent / "data" / "xosc" / "catalogs"


@pytest.fixture
def inline(tmp_path: Path) -> Path:
    """A copy of the catalogs' inline.xosc (an export of CPNA-25/20kph/day), to edit."""
    shutil.copytree(DATA, tmp_path / "case")
    return tmp_path / "case" / "inline.xosc"


def _declare(name: str, value: str) -> str:
    return f'<ParameterDeclarations><ParameterDeclaration name="{name}" parameterType="double" value="{value}"/>' + (
        "</ParameterDeclarations>"
    )


def test_a_maneuver_parameter_reaches_its_events(inline):
    edited(inline, '<Maneuver name="vru0_maneuver">', '<Maneuver name="vru0_maneuver">' + _declare("Top", "1.7"))
    edited(inline, 'AbsoluteTargetSpeed value="$Vru0TopSpeed_mps"', 'AbsoluteTargetSpeed value="$Top"')
    assert read_xosc(inline).vrus[0].top_speed_mps == 1.7


def test_an_inner_declaration_hides_the_outer_one_only_inside(inline):
    edited(
        inline,
        '<Maneuver name="vru0_maneuver">',
        '<Maneuver name="vru0_maneuver">' + _declare("Vru0TopSpeed_mps", "2.5"),
    )
    scenario = read_xosc(inline)
    assert scenario.vrus[0].top_speed_mps == 2.5
    assert scenario.ego.cruise_speed_mps == pytest.approx(5.555555555555555)  # outside: untouched


def test_a_story_parameter_reaches_its_acts_and_an_expression_sees_the_outer_ones(inline):
    edited(
        inline,
        '<Story name="vrusim_story">',
        '<Story name="vrusim_story">' + _declare("Top", "${$Vru0TopSpeed_mps * 2}"),
    )
    edited(inline, 'AbsoluteTargetSpeed value="$Vru0TopSpeed_mps"', 'AbsoluteTargetSpeed value="$Top"')
    assert read_xosc(inline).vrus[0].top_speed_mps == pytest.approx(2 * 1.3888888888888888)


def test_a_trajectory_parameter_reaches_its_vertices(inline):
    edited(
        inline,
        '<Trajectory name="vru0_path" closed="false">',
        '<Trajectory name="vru0_path" closed="false">' + _declare("EndY", "9.5"),
    )
    edited(inline, 'y="8.443333333333332"', 'y="$EndY"')
    scenario = read_xosc(inline)
    assert scenario.vrus[0].heading_deg == pytest.approx(90.0)


def test_an_inline_entity_parameter_reaches_its_fields(inline):
    edited(
        inline,
        '<Vehicle name="ego" vehicleCategory="car" mass="1500.0">',
        '<Vehicle name="ego" vehicleCategory="car" mass="1500.0">' + _declare("Long", "4.9"),
    )
    edited(inline, 'length="4.5"', 'length="$Long"')
    assert read_xosc(inline).ego.length_m == pytest.approx(4.9)


def test_a_parameter_is_not_seen_outside_its_element(inline):
    edited(inline, '<Maneuver name="vru0_maneuver">', '<Maneuver name="vru0_maneuver">' + _declare("Top", "1.7"))
    edited(inline, 'value="$SimDuration_s"', 'value="$Top"')
    refused(inline, "SimulationTimeCondition", "parameter 'Top' is not declared")
