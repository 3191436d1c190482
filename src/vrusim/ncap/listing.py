"""The catalogue as data: one JSON-ready row per Euro NCAP scenario (`vrusim list`)."""

from __future__ import annotations

from vrusim.ncap.editions import edition
from vrusim.ncap.protocol import DUMMIES, NcapScenario

_RANGES = ("standard", "extended", "robustness")


def _target_speeds(spec: NcapScenario) -> list[float] | str:
    """Target speeds of a scenario's grid, km/h; "vut" when the target drives at the VUT's speed (CMRb)."""
    if spec.headway_s > 0:
        return "vut"
    return sorted({round(c.target_speed_kph if c.target_speed_kph is not None else spec.target_speed_kph, 2)
                   for c in spec.cells})  # fmt: skip


def catalogue_listing(protocol: str | None = None) -> list[dict]:
    """One row per scenario of an edition (default: the default edition): its parameters, geometry
    (non-zero fields) and UNVERIFIED flags."""
    rows = []
    for s in edition(protocol).scenarios:
        targets = sorted({c.target or s.target for c in s.cells})
        locations = sorted({c.impact_location if c.impact_location is not None else s.impact_location for c in s.cells})
        geometry = {
            "layout": s.layout,
            "side": s.side,
            "turn": s.turn,
            "lateral_offset_m": s.lateral_offset_m,
            "start_to_impact_m": s.start_to_impact_m,
            "accel_distance_m": s.accel_distance_m,
            "steady_distance_m": s.steady_distance_m,
            "target_line_m": s.target_line_m,
            "headway_s": s.headway_s,
            "target_decel_mps2": s.target_decel_mps2,
        }
        rows.append(
            {
                "code": s.code,
                "group": s.group,
                "description": s.description,
                "function": s.function,
                "targets": targets,
                "target_speeds_kph": _target_speeds(s),
                "vut_speeds_kph": sorted({c.vut_speed_kph for c in s.cells}),
                "variants": [c.variant for c in s.cells if c.variant],
                "impact_locations_pct": [round(100 * x) for x in locations],
                "impact_side": s.impact_side,
                "geometry": {k: v for k, v in geometry.items() if v not in (0.0, None)},
                "lighting": list(s.lighting),
                "obstruction": s.obstruction,
                "extension": s.extension,
                "unverified": list(s.unverified) + [f"{t}: {flag}" for t in targets for flag in DUMMIES[t].unverified],
                "sources": s.sources,
                "tests": len(s.cells) * len(s.lighting),
                "ranges": {r: sum(c.range == r for c in s.cells) * len(s.lighting) for r in _RANGES},
                "official": s.official,
            }
        )
    return rows
