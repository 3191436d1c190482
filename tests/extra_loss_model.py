"""A test-only V2X loss model, added from outside the package: drop every n-th generated message.

`register()` adds it under `loss.model: every_nth` (schema, packing and a NumPy decision); `unregister()`
removes it. No file of vrusim is edited to add it.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from pydantic import Field

from vrusim.scenario.v2x import LossSpec
from vrusim.sim.v2x.loss.registry import LossContext, register_loss_model, unregister_loss_model

NAME = "every_nth"


class EveryNthLoss(LossSpec):
    """Messages number every, 2·every, ... (counted per VRU from 1) are lost; the others arrive."""

    model: Literal["every_nth"] = "every_nth"
    every: int = Field(ge=2, description="drop each message whose number is a multiple of this")


def pack(spec: EveryNthLoss) -> tuple[float, ...]:
    return (float(spec.every),)


def lost(context: LossContext) -> np.ndarray:
    rows = context.rows
    number = context.generated[rows] + 1  # the number of the message generated now, per VRU
    every = context.params[rows, 0:1].astype(np.int64)
    return context.generate[rows] & (number % every == 0)


def register() -> None:
    register_loss_model(EveryNthLoss, pack, lost)


def unregister() -> None:
    unregister_loss_model(NAME)
