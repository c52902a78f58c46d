"""Grid search baselines for EPBHA: the grid, A* and D* Lite."""
