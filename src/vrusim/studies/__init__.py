"""Studies built on runs: planner / V2X comparisons with Wilson intervals, V2X latency and loss sensitivity."""
