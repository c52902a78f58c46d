"""Pure path-planning algorithms of the thesis and their baselines: no I/O, no clocks.

Shared pieces sit at the top (`geometry`: boxes and the world; `proximity` and `cone`: the
thesis's proximity sensors; `kinematic`: exact moves for fast benchmarks; `scenes`: the test
rooms), each planner family in its own package: `epbha` (obstacle avoidance), `flocking`
(leader–follower formations), `radiation` (contour mapping) and `search` (the grid baselines,
A* and D* Lite).
"""
