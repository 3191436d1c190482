"""Interoperability: OpenSCENARIO / OpenDRIVE export, CommonRoad export (Gymnasium environments: vrusim.gym)."""
