"""Where the example files shipped with vrusim live: inside an installed wheel, or in the source checkout.

The wheel carries the repository's `scenarios/` and `sweeps/` folders side by side under `vrusim/_data/`
(pyproject.toml, `force-include`), so a sweep spec's relative `base: ../scenarios/...` resolves in both places.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

from vrusim.errors import UserInputError

PACKAGED = "_data"
"""Folder inside the installed package that holds the bundled folders."""


def _package_folder() -> Path:
    """The folder of the imported `vrusim` package."""
    return Path(str(resources.files("vrusim")))


def bundled_dir(name: str) -> Path:
    """The bundled folder `name` ("scenarios" or "sweeps"); a UserInputError when this installation lacks it."""
    packaged = _package_folder() / PACKAGED / name
    if packaged.is_dir():
        return packaged
    checkout = Path(__file__).resolve().parents[3] / name
    if checkout.is_dir():
        return checkout
    raise UserInputError(f"the bundled {name} folder is missing from this installation")
