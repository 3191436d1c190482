"""Record vrusim's results for a before/after comparison of a refactor, and compare two records bit for bit.

    python scripts/behaviour_snapshot.py record DIR      # paper, Euro NCAP (3 planners x V2X off/on), 20k sweep
    python scripts/behaviour_snapshot.py compare OLD NEW  # exit 1 and a list of differences unless identical

What is recorded, through the `vrusim` command of the running Python (`python -m vrusim`):
- `vrusim paper --json`;
- `vrusim ncap --night --json` for the FSM, AEB and predictive planners, V2X off and on;
- a 20,000-variant Monte Carlo (the bundled pedestrian spec with `samples: 20000`), its Parquet rows sorted by
  variant id.
Numbers are compared exactly (floats by their bits, NaN equal to NaN); keys that name the code version, a path or
a time are left out (`IGNORED_KEYS`).
"""

from __future__ import annotations

import json
import math
import shutil
import struct
import subprocess
import sys
from pathlib import Path

import pyarrow.parquet as pq
import yaml

ROOT = Path(__file__).resolve().parent.parent
PLANNERS = ("fsm", "aeb", "predictive")
SWEEP_SAMPLES = 20_000
IGNORED_KEYS = {"version", "source_digest", "code", "elapsed_s", "wall_s", "seconds", "out", "path", "created"}
"""Keys whose values name the code version, a file or a time, not a result."""


def _vrusim(*args: str) -> str:
    done = subprocess.run([sys.executable, "-m", "vrusim", *args], capture_output=True, text=True, check=False)
    if done.returncode != 0:
        sys.exit(f"vrusim {' '.join(args)} failed ({done.returncode}):\n{done.stderr}")
    return done.stdout


def _sweep_spec(folder: Path) -> Path:
    spec = yaml.safe_load((ROOT / "sweeps" / "pedestrian_monte_carlo.yaml").read_text())
    spec["base"] = str(ROOT / "scenarios" / "paper" / "pedestrian_crossing.yaml")
    spec["samples"] = SWEEP_SAMPLES
    path = folder / "sweep_spec.yaml"
    path.write_text(yaml.safe_dump(spec))
    return path


def record(folder: Path) -> None:
    """Write every result named in the module docstring into `folder` (created; must not exist)."""
    folder.mkdir(parents=True)
    (folder / "paper.json").write_text(_vrusim("paper", "--json"))
    for planner in PLANNERS:
        for v2x in ("off", "on"):
            text = _vrusim("ncap", "--night", "--json", "--planner", planner, "--v2x", v2x)
            (folder / f"ncap_{planner}_v2x_{v2x}.json").write_text(text)
    sweep_out = folder / "sweep_run"
    _vrusim("sweep", str(_sweep_spec(folder)), "--out", str(sweep_out), "--quiet")
    table = pq.read_table(sorted((sweep_out / "chunks").rglob("*.parquet")) or sweep_out / "chunks")
    rows = table.sort_by("variant").to_pylist()
    (folder / "sweep_rows.json").write_text(json.dumps(rows, default=_bits, sort_keys=True))
    shutil.rmtree(sweep_out)


def _bits(value: object) -> object:
    return repr(value)


def _same(a: object, b: object, where: str, out: list[str]) -> None:
    if isinstance(a, dict) and isinstance(b, dict):
        for key in sorted(set(a) | set(b), key=str):
            if key in IGNORED_KEYS:
                continue
            if key not in a or key not in b:
                out.append(f"{where}.{key}: only in {'new' if key in b else 'old'}")
            else:
                _same(a[key], b[key], f"{where}.{key}", out)
    elif isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            out.append(f"{where}: {len(a)} items before, {len(b)} after")
        for i, (x, y) in enumerate(zip(a, b, strict=False)):
            _same(x, y, f"{where}[{i}]", out)
    elif isinstance(a, float) and isinstance(b, float):
        if not (math.isnan(a) and math.isnan(b)) and struct.pack("<d", a) != struct.pack("<d", b):
            out.append(f"{where}: {a!r} before, {b!r} after")
    elif a != b or type(a) is not type(b):
        out.append(f"{where}: {a!r} before, {b!r} after")


def compare(old: Path, new: Path) -> int:
    """Print every difference between two records; 0 when they are identical."""
    differences: list[str] = []
    names = sorted({p.name for p in old.glob("*.json")} | {p.name for p in new.glob("*.json")})
    for name in names:
        if not (old / name).exists() or not (new / name).exists():
            differences.append(f"{name}: missing in one record")
            continue
        _same(json.loads((old / name).read_text()), json.loads((new / name).read_text()), name, differences)
    for line in differences[:200]:
        print(line)
    print(f"{len(names)} files compared, {len(differences)} differences")
    return 1 if differences else 0


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "record":
        record(Path(sys.argv[2]))
    elif len(sys.argv) == 4 and sys.argv[1] == "compare":
        sys.exit(compare(Path(sys.argv[2]), Path(sys.argv[3])))
    else:
        sys.exit(__doc__)
