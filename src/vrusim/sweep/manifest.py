"""The manifest of a sweep results folder (`manifest.json`): read and checked in this one place.

Every reader (`--resume`, `--force`, `vrusim summarize`, `vrusim report`) goes through `read_manifest`, so a
hand-edited or foreign manifest ends in one message naming the file and the key, never in a traceback later.
Keys vrusim writes are checked for their type when present; `format` and `parameters` are always needed, and
`--resume` also needs the recorded `plan` and its digest (`RESUME_KEYS`).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from vrusim.errors import UserInputError
from vrusim.io.paths import shown

FORMAT = "vrusim-sweep/1"
MANIFEST = "manifest.json"
RESUME_KEYS = ("plan", "plan_sha256")
"""Keys `--resume` needs besides those every reader needs."""

_TYPES: dict[str, tuple[type, ...]] = {
    "name": (str,),
    "spec": (dict,),
    "base_file": (str, type(None)),
    "code": (dict,),
    "plan": (dict,),
    "plan_sha256": (str,),
    "created_utc": (str,),
}
_COUNTS = ("variants", "grid_points", "samples", "batch_size", "chunks", "seed")
"""Keys holding a whole number ≥ 0."""
_TYPE_NAMES = {str: "a string", dict: "an object", type(None): "null"}
_PLAN_KEYS: dict[str, tuple[type, ...]] = {
    "name": (str,),
    "bases": (dict,),
    "parameters": (list,),
    "samples": (int,),
    "seed": (int,),
    "batch_size": (int,),
}


def _is_count(value: Any) -> bool:
    return isinstance(value, int) and not isinstance(value, bool) and value >= 0


def check_manifest(manifest: Any, path: Path, needed: tuple[str, ...] = ()) -> dict[str, Any]:
    """`manifest` if it has the structure vrusim writes (and the keys `needed`), else a UserInputError naming
    `path` and the first wrong key."""
    where = shown(path)
    if not isinstance(manifest, dict):
        raise UserInputError(f"{where}: expected a JSON object")
    if manifest.get("format") != FORMAT:
        raise UserInputError(f"{where}: format: expected {FORMAT!r}, got {manifest.get('format')!r}")
    parameters = manifest.get("parameters")
    if not isinstance(parameters, list) or not all(
        isinstance(entry, dict) and isinstance(entry.get("name"), str) for entry in parameters
    ):
        raise UserInputError(f"{where}: parameters: expected a list of objects with a 'name'")
    for key in needed:
        if key not in manifest:
            raise UserInputError(f"{where}: {key}: missing (was the manifest edited?)")
    for key, types in _TYPES.items():
        if key in manifest and not isinstance(manifest[key], types):
            expected = " or ".join(_TYPE_NAMES[t] for t in types)
            raise UserInputError(f"{where}: {key}: expected {expected}, got {manifest[key]!r:.60}")
    for key in _COUNTS:
        if key in manifest and not _is_count(manifest[key]):
            raise UserInputError(f"{where}: {key}: expected a whole number ≥ 0, got {manifest[key]!r:.60}")
    if "plan" in manifest:
        for key, types in _PLAN_KEYS.items():
            value = manifest["plan"].get(key)
            if not isinstance(value, types) or isinstance(value, bool):
                raise UserInputError(f"{where}: plan.{key}: missing or of the wrong type (was the manifest edited?)")
    return manifest


def read_manifest(folder: Path, needed: tuple[str, ...] = ()) -> dict[str, Any]:
    """The checked manifest of the results folder `folder` (`check_manifest`); a missing or unreadable one is a
    UserInputError naming it."""
    path = folder / MANIFEST
    if not path.is_file():
        raise UserInputError(f"{shown(folder)}: not a sweep results folder (no {MANIFEST}; written by vrusim sweep)")
    try:
        manifest = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError) as error:
        raise UserInputError(f"{shown(path)}: cannot read ({error})") from None
    except json.JSONDecodeError as error:
        raise UserInputError(f"{shown(path)}: not valid JSON ({error.msg} at line {error.lineno})") from None
    except RecursionError:
        raise UserInputError(f"{shown(path)}: not valid JSON (nested too deeply)") from None
    return check_manifest(manifest, path, needed)
