"""A scenario mapping as YAML text, as `vrusim import` writes it and reports show it.

PyYAML's safe dumper with the keys in model order; the points of a drawn road (`road.lines`, `road.surfaces`)
are written one `[x, y]` per line instead of three lines each. Without a drawn road the text is exactly
`yaml.safe_dump(data, sort_keys=False, allow_unicode=True)`.
"""

from __future__ import annotations

from typing import Any

import yaml


class _Pair(list):
    """A point, written in flow style: `[x, y]`."""


class _Dumper(yaml.SafeDumper):
    """The safe dumper that also writes `_Pair`s in flow style."""


_Dumper.add_representer(_Pair, lambda dumper, pair: dumper.represent_sequence("tag:yaml.org,2002:seq", pair, True))


def _with_flow_points(data: dict[str, Any]) -> dict[str, Any]:
    road = data.get("road")
    if not isinstance(road, dict) or not (road.get("lines") or road.get("surfaces")):
        return data
    drawn = {
        name: [{**item, "points": [_Pair(point) for point in item["points"]]} for item in road[name]]
        for name in ("lines", "surfaces")
        if road.get(name)
    }
    return {**data, "road": {**road, **drawn}}


def scenario_yaml(data: dict[str, Any]) -> str:
    """`data` (a scenario's JSON-mode dump) as YAML text."""
    return yaml.dump(_with_flow_points(data), Dumper=_Dumper, sort_keys=False, allow_unicode=True)
