"""The paper's three case studies: Table II, caption events, reproduce() and match counts."""
