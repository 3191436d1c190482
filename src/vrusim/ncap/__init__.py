"""The Euro NCAP AEB VRU protocol: protocol tables, test to Scenario, running the grid, assessment and points."""
