"""V2X loss models, one module each, behind a registry by name (`vrusim.sim.v2x.loss.registry`).

The built-in modules register themselves when imported; `vrusim.sim.v2x.kernels` imports them all.
"""
