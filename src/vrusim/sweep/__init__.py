"""Parameter sweeps and Monte Carlo studies: spec, design, execution, results store and analysis."""
