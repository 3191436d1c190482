"""The Euro NCAP VRU protocols by edition (2023: v4.5.1; 2026: FC26 / LSC26): tables, test to Scenario, the grid,
assessment, points, predictions for the official calculator and the simulated lab verification."""
