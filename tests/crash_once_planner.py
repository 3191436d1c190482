"""A test plug-in planner that kills a worker process the first time it is reset there (a worker dying mid-sweep).

The marker file named by $VRUSIM_CRASH_MARKER records the crash, so the batch succeeds when it runs again.
"""

from __future__ import annotations

import multiprocessing
import os
from pathlib import Path

from vrusim.planners.base import HoldSpeedPlanner


class CrashOnce(HoldSpeedPlanner):
    """Holds speed; the first reset in a worker process kills that process (like SIGKILL: no cleanup)."""

    def reset(self, params) -> None:
        marker = Path(os.environ["VRUSIM_CRASH_MARKER"])
        if multiprocessing.parent_process() is not None and not marker.exists():
            marker.write_text("crashed\n")
            os._exit(9)
        super().reset(params)
