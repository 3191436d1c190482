"""Scene players of chosen tests of a Euro NCAP assessment (`vrusim report FOLDER --player TEST-ID`): each test is
run again as it ran in the assessment (its edition, planner and V2X setting) with a trace."""

from __future__ import annotations

import re
from collections.abc import Sequence
from typing import Any

from vrusim.errors import UserInputError
from vrusim.report.page import Section
from vrusim.report.player import player
from vrusim.sources import apply_planner_and_seed, scenario_of
from vrusim.viz.recording import record


def test_players(rows: Sequence[dict[str, Any]], test_ids: Sequence[str]) -> list[Section]:
    """One section with a player per test id; an id not among the assessment's rows is a user error."""
    by_id = {str(row["test_id"]): row for row in rows}
    sections = []
    for test_id in dict.fromkeys(test_ids):
        row = by_id.get(test_id)
        if row is None:
            shown = ", ".join(sorted(by_id)[:8]) + (", …" if len(by_id) > 8 else "")
            raise UserInputError(f"--player: test {test_id!r} is not in this assessment; its tests include {shown}")
        edition = row.get("protocol")
        source = f"{edition}:{test_id}" if edition else test_id
        scenario = scenario_of(source, bool(row.get("v2x")), argument="--player")
        scenario = apply_planner_and_seed(scenario, row.get("planner"), None)
        recording = record([scenario])[0]
        slug = re.sub(r"[^A-Za-z0-9]+", "-", test_id).strip("-").lower()
        title = f"Scene player: {test_id}"
        sections.append(Section(f"scene-player-{slug}", title, player([recording], f"player-{slug}", labels=[test_id])))
    return sections
