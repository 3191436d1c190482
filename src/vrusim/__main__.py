"""`python -m vrusim`: the same command line as the `vrusim` console script.

`python -m` puts the current folder first on `sys.path`; it is taken off, so a module that happens to lie there
(an `evil.py` next to a scenario file) is never imported by a planner name (docs/planners.md, "Plug-ins").
"""

import os
import sys

if sys.path and sys.path[0] in ("", os.getcwd()):
    del sys.path[0]

from vrusim.cli.app import main

if __name__ == "__main__":
    main(prog_name="python -m vrusim")
