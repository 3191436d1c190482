"""Onboard sensing: the sector sensor, line-of-sight occlusion by obstacles, the realistic sensor model."""
