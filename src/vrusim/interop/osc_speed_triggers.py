"""Export a VRU trigger on the ego's speed as the matching OpenSCENARIO condition of the ego.

`ego_speed_below_mps` -> SpeedCondition rule lessOrEqual, `ego_speed_above_mps` -> SpeedCondition rule
greaterOrEqual, `ego_standstill_s` -> StandStillCondition duration (the importer reads them back to the same
trigger: `vrusim.formats.xosc_speed_conditions`).
"""

from __future__ import annotations

from collections.abc import Callable

from vrusim.extras import extra

with extra("export"):
    from scenariogeneration import xosc

from vrusim.scenario.schema import Trigger


def ego_speed_trigger(
    trigger: Trigger, ego: str, name: str, ref: Callable[[str, float], str], prefix: str
) -> tuple[object, str] | None:
    """(start condition `name` on entity `ego`, note) of a trigger on the ego's speed; None for other triggers.
    `ref(name, value)` declares a parameter and returns its reference; `prefix` starts the parameter names."""
    if trigger.ego_speed_below_mps is not None:
        value = ref(f"{prefix}TriggerEgoSpeed_mps", trigger.ego_speed_below_mps)
        condition = xosc.SpeedCondition(value, xosc.Rule.lessOrEqual)
        note = f"ego speed <= {trigger.ego_speed_below_mps!r} m/s"
    elif trigger.ego_speed_above_mps is not None:
        value = ref(f"{prefix}TriggerEgoSpeed_mps", trigger.ego_speed_above_mps)
        condition = xosc.SpeedCondition(value, xosc.Rule.greaterOrEqual)
        note = f"ego speed >= {trigger.ego_speed_above_mps!r} m/s"
    elif trigger.ego_standstill_s is not None:
        value = ref(f"{prefix}TriggerEgoStandStill_s", trigger.ego_standstill_s)
        condition = xosc.StandStillCondition(value)
        note = f"ego stood still for {trigger.ego_standstill_s!r} s"
    else:
        return None
    return xosc.EntityTrigger(name, 0.0, xosc.ConditionEdge.none, condition, ego), note
