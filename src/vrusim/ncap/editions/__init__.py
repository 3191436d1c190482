"""Euro NCAP protocol editions by name: each one a scenario table (and, in `ncap/`, its assessment rules).

`2023` is the AEB/LSS VRU protocol v4.5.1 (rating years 2023–2025); `2026` the Crash Avoidance protocols
FC26 and LSC26 (in force since January 2026). The command line takes the name as `--protocol`.
"""

from __future__ import annotations

from dataclasses import dataclass
from importlib import import_module

from vrusim.errors import UserInputError
from vrusim.ncap.protocol import NcapScenario


@dataclass(frozen=True)
class Edition:
    """One edition of the Euro NCAP VRU test protocols: its name, title, source texts and scenario table."""

    name: str
    title: str
    sources: str
    scenarios: tuple[NcapScenario, ...]

    def scenario(self, code: str) -> NcapScenario:
        """The scenario with this exact code (KeyError if absent)."""
        for spec in self.scenarios:
            if spec.code == code:
                return spec
        raise KeyError(code)

    @property
    def codes(self) -> tuple[str, ...]:
        """Every scenario code, in table order."""
        return tuple(s.code for s in self.scenarios)


_MODULES = {"2023": "vrusim.ncap.editions.v2023", "2026": "vrusim.ncap.editions.v2026"}
"""Edition name -> the module whose EDITION it is (imported on first use)."""

EDITION_NAMES: tuple[str, ...] = tuple(_MODULES)
DEFAULT_EDITION = "2026"
"""The edition used when none is named."""


def edition(name: str | None = None) -> Edition:
    """The edition called `name` (default: DEFAULT_EDITION); a UserInputError naming `--protocol` otherwise."""
    chosen = DEFAULT_EDITION if name is None else str(name).strip()
    if chosen not in _MODULES:
        raise UserInputError(f"--protocol: unknown edition {name!r}; expected one of: {', '.join(EDITION_NAMES)}")
    return import_module(_MODULES[chosen]).EDITION
