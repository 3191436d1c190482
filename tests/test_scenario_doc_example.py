"""docs/scenario.md's "Complete example" is the paper's pedestrian case with every optional field spelled out:
it validates, it is that case, and it names every field the scenario model has (a new field must be added)."""

from __future__ import annotations

from pathlib import Path

import yaml

import vrusim
from vrusim.scenario.loading import load_scenario

DOC = Path(__file__).resolve().parents[1] / "docs" / "scenario.md"
ALTERNATIVES = {"vrus[0].path"} | {
    f"vrus[0].trigger.{condition}"
    for condition in (
        "ego_distance_m",
        "ego_route_m",
        "ego_speed_above_mps",
        "ego_speed_below_mps",
        "ego_standstill_s",
        "ego_time_to_arrival_s",
        "point",
    )
}
"""Fields the example leaves out because it uses one of their alternatives: `heading_deg` instead of a `path`, and
a trigger `at_time_s` instead of any other condition."""


def _example_text() -> str:
    section = DOC.read_text(encoding="utf-8").split("## Complete example", 1)[1]
    return section.split("```yaml\n", 1)[1].split("```", 1)[0]


def _field_paths(value, prefix: str = "") -> set[str]:
    """Dotted paths of every mapping key in `value`, lists entered through their first item."""
    if isinstance(value, dict):
        paths = set()
        for key, item in value.items():
            path = f"{prefix}.{key}" if prefix else key
            paths |= {path} | _field_paths(item, path)
        return paths
    if isinstance(value, list) and value and isinstance(value[0], dict):
        return _field_paths(value[0], prefix + "[0]")
    return set()


def test_the_complete_example_is_the_paper_pedestrian_case(tmp_path):
    path = tmp_path / "complete.yaml"
    path.write_text(_example_text())
    example = load_scenario(path).model_dump()
    paper = vrusim.load("paper:pedestrian").model_dump()
    for field in ("radius_m", "max_accel_mps2"):  # written out at the type default, which the model keeps as None
        assert paper["vrus"][0][field] is None
        paper["vrus"][0][field] = example["vrus"][0][field]
    assert example == paper


def test_the_complete_example_names_every_field():
    written = _field_paths(yaml.safe_load(_example_text()))
    model = _field_paths(vrusim.load("paper:pedestrian").model_dump(mode="json"))
    assert model - written - ALTERNATIVES == set()
    assert model >= ALTERNATIVES  # still fields of the model
