"""The step loop: one step of a batch, simulate() over a horizon, streaming accumulators, traces and trace files."""
