"""Optional features and the pip extra that installs each (pyproject.toml, [project.optional-dependencies]).

The core install runs scenarios, Euro NCAP assessment, sweeps, figures and reports. Libraries that serve one
feature come with an extra and are imported only by that feature's modules, inside `with extra(name):`, which
turns their absence into one clear message (a MissingExtraError: exit code 2 at the command line):

    with extra("export"):
        from scenariogeneration import xodr, xosc

    -> vrusim export needs the 'export' extra (scenariogeneration is not installed): pip install 'vrusim[export]'
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass

from vrusim.errors import UserInputError


class MissingExtraError(UserInputError, ImportError):
    """A feature's extra is not installed. A UserInputError (exit code 2 at the command line) and an ImportError
    (`except ImportError` around `import vrusim.gym` works as for any optional package)."""


@dataclass(frozen=True)
class Extra:
    """What an extra enables (the subject of the message) and its packages: top-level module -> PyPI name."""

    feature: str
    packages: dict[str, str]


EXTRAS: dict[str, Extra] = {
    "export": Extra(
        "vrusim export",
        {"scenariogeneration": "scenariogeneration", "commonroad": "commonroad-io", "shapely": "shapely"},
    ),
    "gym": Extra("vrusim.gym (the Gymnasium environments)", {"gymnasium": "gymnasium"}),
    "ncap2026": Extra(
        "Euro NCAP 2026 predictions and official scoring (vrusim ncap --predictions)",
        {"euroncap_rating_2026": "euroncap-rating-2026"},
    ),
    "dask": Extra("--scheduler (a Dask cluster)", {"dask": "dask", "distributed": "distributed"}),
    "video": Extra("an MP4 animation", {"imageio_ffmpeg": "imageio-ffmpeg"}),
    "pandas": Extra("to_pandas()", {"pandas": "pandas"}),
}
"""Every extra but `all` (all of these) and `test` (all, and the test tools)."""


def missing_extra_message(name: str, module: str) -> str:
    """The message for a feature of extra `name` whose top-level `module` is not installed."""
    package = EXTRAS[name].packages[module]
    return f"{EXTRAS[name].feature} needs the '{name}' extra ({package} is not installed): pip install 'vrusim[{name}]'"


@contextmanager
def extra(name: str) -> Iterator[None]:
    """Run imports that need the extra `name`; a module of it that is missing (ModuleNotFoundError naming it or
    one of its submodules) becomes a MissingExtraError that says what to install. Other errors pass unchanged: a
    missing dependency *of* an installed library is a broken install, not a missing extra."""
    if name not in EXTRAS:
        raise ValueError(f"unknown extra {name!r}; known: {', '.join(EXTRAS)}")
    try:
        yield
    except ModuleNotFoundError as error:
        top = (error.name or "").partition(".")[0]
        if top not in EXTRAS[name].packages:
            raise
        raise MissingExtraError(missing_extra_message(name, top)) from None
