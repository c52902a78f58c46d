"""Pure path-planning algorithms of the thesis and their baselines: no I/O, no clocks."""
