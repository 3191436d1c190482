"""Interoperability: OpenSCENARIO / OpenDRIVE export, OpenDRIVE import (roads), CommonRoad export (Gymnasium
environments: vrusim.gym)."""
