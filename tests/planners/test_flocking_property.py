"""Property: on random cluttered rooms the triangular flock never collides nor closes up."""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from gcs.mission.kinematic_flock import fly_flock_scene
from planners.flocking.planner import FlockParams
from planners.flocking.scenes import CRUISE_Z_M, ROOM, FlockScene
from planners.flocking.swarm import FlockPlannerKind
from planners.geometry import Box, World


@st.composite
def scenes(draw: st.DrawFn) -> tuple[FlockScene, int]:
    """Up to four pillars or low boxes between start and goal, and a team of 3–5."""
    boxes = []
    for i in range(draw(st.integers(0, 4))):
        x0 = draw(st.floats(6.5, 10.0))
        y0 = draw(st.floats(-3.0, 2.5))
        sx = draw(st.floats(0.2, 1.2))
        sy = draw(st.floats(0.2, 1.5))
        top_alt = draw(st.sampled_from([0.6, 3.0]))  # a low crate to fly over, or a pillar
        boxes.append(Box(f"b{i}", (x0, y0, -top_alt), (x0 + sx, y0 + sy, 0.0)))
    scene = FlockScene(
        name="random",
        world=World(ROOM, tuple(boxes)),
        leader_start_n=(4.0, 0.0, CRUISE_Z_M),
        common_goal_n=(13.0, draw(st.floats(-1.0, 1.0)), CRUISE_Z_M),
    )
    return scene, draw(st.integers(3, 5))


@settings(max_examples=30, deadline=None)
@given(scenes(), st.integers(0, 2**31 - 1))
def test_no_collision_and_separation_above_safe_distance(
    case: tuple[FlockScene, int], seed: int
) -> None:
    scene, n = case
    r = fly_flock_scene(scene, n, FlockPlannerKind.TRIANGULAR, 250, np.random.default_rng(seed))
    assert r.obstacle_collisions == 0
    assert r.vehicle_collisions == 0
    assert r.min_separation_m >= FlockParams().formation.safe_distance_m - 1e-9
