"""The Euro NCAP catalogue: select tests, run them as one batch, hand the results to the assessment."""

from __future__ import annotations

import functools
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

from vrusim.engine.simulate import BatchRun, simulate
from vrusim.errors import UserInputError
from vrusim.limits import limits_held
from vrusim.metrics.summary import summary_rows
from vrusim.ncap.build import BuiltTest, NcapTest, build_test
from vrusim.ncap.build_low_speed import LOW_SPEED_LAYOUTS
from vrusim.ncap.editions import edition
from vrusim.ncap.probes import batched_probes
from vrusim.ncap.protocol import KPH, NcapScenario
from vrusim.planners.base import planner_warning
from vrusim.planners.registry import make_planner


def scenario_codes(protocol: str | None = None) -> list[str]:
    """Every scenario code of an edition (default: the default edition), in table order."""
    return list(edition(protocol).codes)


def select(codes: Sequence[str] | None = None, night: bool = False, protocol: str | None = None) -> list[NcapTest]:
    """The tests of the chosen scenarios of an edition (all when `codes` is empty): every cell, day, plus
    night if asked. `protocol` names the edition (ncap/editions; default: the default edition).

    A code selects every scenario whose code starts with it, ignoring case: in 2023, `CPNA-25` one scenario,
    `CPTA` the four CPTA scenarios, `CMRs` both CMRs rows, `CB` every cyclist scenario.
    """
    book = edition(protocol)
    chosen: list[NcapScenario] = []
    for code in codes or []:
        wanted = code.strip().upper()
        matches = [s for s in book.scenarios if s.code.upper().startswith(wanted)] if wanted else []
        if not matches:
            raise UserInputError(
                f"--scenario: unknown {book.name} catalogue entry {code!r}; expected one of: {', '.join(book.codes)}"
            )
        chosen.extend(m for m in matches if m not in chosen)
    specs = chosen or list(book.scenarios)
    lightings = ("day", "night") if night else ("day",)
    return [
        NcapTest(spec, cell, lighting, book.name)
        for spec in specs
        for lighting in lightings
        if lighting in spec.lighting
        for cell in spec.cells
    ]


@dataclass
class CatalogueRun:
    """A catalogue batch: the built tests, the batch run, and one result row per test."""

    built: list[BuiltTest]
    run: BatchRun
    rows: list[dict]


def run_tests(tests: Iterable[NcapTest], planner: str = "fsm", v2x: bool = False) -> CatalogueRun:
    """Build every test and run them all as one batch; rows carry what the Euro NCAP assessment needs."""
    tests = list(tests)
    low_speed = [test for test in tests if test.spec.layout in LOW_SPEED_LAYOUTS]
    with limits_held():  # each scenario's bounds are checked against limits read once for the grid
        batched_probes([functools.partial(build_test, test, planner, v2x) for test in low_speed])  # one batch
        built = [build_test(test, planner, v2x) for test in tests]
    if not built:
        raise UserInputError("--scenario: the selection contains no tests")
    driver = make_planner(planner)
    run = simulate([b.scenario for b in built], planner=driver)
    warns = planner_warning(driver) is not None  # a planner that warns exposes `warning` once reset
    rows = []
    for b, summary in zip(built, summary_rows(run), strict=True):
        test = b.test
        impact_speed = summary["impact_ego_speed_mps"]
        rel_long = summary["impact_relative_longitudinal_speed_mps"]
        target_long = None if impact_speed is None or rel_long is None else round(impact_speed - rel_long, 6)
        rows.append(
            {
                "test_id": test.test_id,
                "protocol": test.protocol,
                "scenario": test.spec.code,
                "group": test.spec.group,
                "function": test.cell.function or test.spec.function,
                "lighting": test.lighting,
                "vut_speed_kph": test.cell.vut_speed_kph,
                "variant": test.cell.variant,
                "target": test.dummy.code,
                "target_speed_kph": round(test.target_speed_mps / KPH, 3),
                "impact_location": test.impact_location,
                "range": test.cell.range,
                "grid_row": test.cell.row_label,
                "official_scenario": test.spec.official.format(lighting=test.lighting),
                "extension": test.spec.extension,
                "planner": planner,
                "v2x": v2x,
                "collided": summary["collided"],
                "impact_speed_mps": impact_speed,
                "target_longitudinal_speed_mps": target_long,
                "contact_time_s": summary["contact_time_s"],
                "first_sensor_detection_s": summary["first_sensor_detection_s"],
                "first_v2x_message_s": summary["first_v2x_message_s"],
                "min_ttc_s": summary["min_ttc_s"],
                "min_clearance_m": summary["min_clearance_m"],
                "peak_decel_mps2": summary["peak_decel_mps2"],
                "warning_ttc_s": summary["warning_ttc_s"],
                "planner_warns": warns,
                "nominal_impact_time_s": round(b.nominal.time_s, 6),
            }
        )
    return CatalogueRun(built, run, rows)
