"""Motion planners: the protocol, the FSM, AEB and predictive planners, conflict and prediction helpers, registry."""
