"""Reynolds baseline: all-to-all message count, separation rule, same targets as the flock."""

import numpy as np
import pytest

from gcs.mission.kinematic_flock import fly_flock_scene
from planners.flocking.planner import FlockMission
from planners.flocking.reynolds import ReynoldsPlanner
from planners.flocking.scenes import open_hall
from planners.flocking.swarm import FlockPlannerKind
from planners.proximity import ProximityReading


def test_messages_are_n_times_n_minus_one_per_step() -> None:
    r = fly_flock_scene(open_hall(), 5, FlockPlannerKind.REYNOLDS, 40, np.random.default_rng(0))
    # 40 moves, 41 plans: the loop plans once more than it moves
    assert r.steps == 40 and r.messages_sent == 41 * 5 * 4


def test_open_hall_is_reached_with_the_flock_s_targets() -> None:
    scene = open_hall()
    r = fly_flock_scene(scene, 5, FlockPlannerKind.REYNOLDS, 400, np.random.default_rng(0))
    assert r.status.value == "reached", r.reason
    assert r.collisions == 0
    tri = fly_flock_scene(scene, 5, FlockPlannerKind.TRIANGULAR, 400, np.random.default_rng(0))
    for v in r.paths_n:
        assert np.allclose(r.paths_n[v][-1], tri.paths_n[v][-1], atol=0.06)


def test_separation_pushes_two_close_vehicles_apart() -> None:
    planner = ReynoldsPlanner(
        [1, 2],
        {1: (10.0, 0.0, -1.0), 2: (10.0, 0.0, -1.0)},
        {1: np.zeros(2), 2: np.zeros(2)},
    )
    pos = {1: (5.0, -0.2, -1.0), 2: (5.0, 0.2, -1.0)}
    clear = ProximityReading.clear()
    out = planner.step(0, pos, {1: clear, 2: clear})
    # Both head for the same goal, yet each veers away from the other.
    assert out.setpoints_n[1][1] < -0.2
    assert out.setpoints_n[2][1] > 0.2
    assert out.setpoints_n[1][0] > 5.0 and out.setpoints_n[2][0] > 5.0


def test_targets_must_cover_every_vehicle() -> None:
    with pytest.raises(ValueError, match="target"):
        ReynoldsPlanner([1, 2], {1: (0.0, 0.0, 0.0)}, {})
    mission = FlockMission((10.0, 0.0, -1.0), {2: (3.0, 3.0, -0.5)})
    p = ReynoldsPlanner.for_mission([1, 2, 3], mission, (1.0, 0.0))
    assert p.final_targets_n()[2] == (3.0, 3.0, -0.5)
