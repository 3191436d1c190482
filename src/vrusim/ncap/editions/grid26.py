"""Grid builders of the 2026 tables: FC26 / LSC26 matrices of VUT speed × impact location (or target speed).

Which cells are standard and which extended is the protocol's cell colour, which the stored text loses; the
values passed in come from the official calculator (`euroncap_rating_2026.crash_avoidance.data_model`
EXTENDED_RANGE_CELLS and the `ca_template.xlsx` matrices), checked cell by cell by
tests/test_ncap_2026_tables.py.
"""

from __future__ import annotations

from collections.abc import Iterable

from vrusim.ncap.protocol import Cell, Function


def il_grid(
    vut_speeds_kph: Iterable[float],
    locations_pct: Iterable[int],
    standard_pct: Iterable[int],
    *,
    extended_speeds_kph: Iterable[float] = (),
    function: Function | None = None,
    target_speed_kph: float | None = None,
    prefix: str = "",
) -> tuple[Cell, ...]:
    """Cells VUT speed × impact location (variant `<prefix>IL<pct>`): standard where the location is in
    `standard_pct` and the speed is not in `extended_speeds_kph`, extended otherwise."""
    standard, extended_rows = set(standard_pct), set(extended_speeds_kph)
    return tuple(
        Cell(
            float(v),
            f"{prefix}IL{pct}",
            impact_location=pct / 100,
            target_speed_kph=target_speed_kph,
            range="standard" if pct in standard and v not in extended_rows else "extended",
            function=function,
        )
        for v in vut_speeds_kph
        for pct in locations_pct
    )


def speed_grid(
    vut_speeds_kph: Iterable[float],
    target_speeds_kph: Iterable[float],
    extended: Iterable[tuple[float, float]],
    *,
    skip: Iterable[tuple[float, float]] = (),
    label: str = "EMT",
) -> tuple[Cell, ...]:
    """Cells VUT speed × target speed (variant `<label><speed>`), without the `skip` pairs (the protocol's
    N/A cells); (VUT, target) pairs in `extended` are extended, the rest standard."""
    extended_pairs, skipped = set(extended), set(skip)
    targets = tuple(target_speeds_kph)
    return tuple(
        Cell(
            float(v),
            f"{label}{t:g}",
            target_speed_kph=float(t),
            range="extended" if (v, t) in extended_pairs else "standard",
        )
        for v in vut_speeds_kph
        for t in targets
        if (v, t) not in skipped
    )
