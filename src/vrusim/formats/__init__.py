"""Scenario files in other formats, read into vrusim scenarios: OpenSCENARIO XML (`.xosc`) with its OpenDRIVE
roads (`.xodr`); safe XML with line numbers (docs/openscenario_import.md, docs/opendrive_import.md)."""
