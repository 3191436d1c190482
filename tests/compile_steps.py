"""Compile, or load from the kernel cache, the compiled step of each built-in planner named on the command line.

Run by the test suite's controller before its workers start (tests/conftest.py), in two processes at once, so that
on a cold kernel cache the workers load these kernels instead of each compiling them.
Usage: python tests/compile_steps.py PLANNER [PLANNER ...]
"""

from __future__ import annotations

import dataclasses
import sys
from pathlib import Path

import numpy as np

from vrusim.engine.simulate import simulate
from vrusim.scenario.loading import load_scenario
from vrusim.scenario.settings import with_settings
from vrusim.sim.params import pack

SCENARIO = Path(__file__).resolve().parents[1] / "scenarios" / "paper" / "pedestrian_crossing.yaml"

if __name__ == "__main__":
    for planner in sys.argv[1:]:
        batch = pack([with_settings(load_scenario(SCENARIO), planner=planner, v2x=True)])
        two_steps = dataclasses.replace(batch, n_steps=2, duration_s=np.full(batch.size, 2 * batch.dt_s))
        simulate(two_steps, compiled=True)
