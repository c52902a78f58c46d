"""The step API a mission runner drives, and the runner's refusals and books."""

import numpy as np
import pytest

from gcs.mission.kinematic_flock import fly_flock_scene
from planners.flocking.formation import Role
from planners.flocking.planner import FlockMission, FlockPlanner, Phase, VehicleMode
from planners.flocking.scenes import FlockScene, open_hall, table_room
from planners.flocking.swarm import FlockPlannerKind
from planners.geometry import Box, World
from planners.proximity import ProximityReading


def test_step_keys_everything_by_vehicle_id() -> None:
    ids = [11, 12, 13, 14, 15]
    planner = FlockPlanner(ids, FlockMission((10.0, 0.0, -1.0)), (1.0, 0.0))
    pos = planner.start_positions_n((2.0, 0.0, -1.0))
    out = planner.step(0, pos, dict.fromkeys(ids, ProximityReading.clear()))
    assert set(out.setpoints_n) == set(ids)
    assert out.roles[11] is Role.LEADER and out.roles[12] is Role.RELAY
    assert out.roles[15] is Role.FOLLOWER
    assert out.phase is Phase.COMMON_GOAL
    assert out.messages_sent == 4  # 11 → 12, 13 and 12 → 14, 15
    assert out.setpoints_n[11] == pytest.approx((2.1, 0.0, -1.0))
    assert out.modes[11] is VehicleMode.FORMATION


def test_step_refuses_missing_vehicles_and_bad_teams() -> None:
    planner = FlockPlanner([1, 2, 3], FlockMission((10.0, 0.0, -1.0)), (1.0, 0.0))
    pos = planner.start_positions_n((2.0, 0.0, -1.0))
    with pytest.raises(ValueError, match=r"no position or reading for \[3\]"):
        planner.step(0, pos, {1: ProximityReading.clear(), 2: ProximityReading.clear()})
    with pytest.raises(ValueError, match="unique"):
        FlockPlanner([1, 1], FlockMission((10.0, 0.0, -1.0)), (1.0, 0.0))
    with pytest.raises(ValueError, match="unknown vehicle ids"):
        FlockPlanner([1, 2], FlockMission((10.0, 0.0, -1.0), {7: (0.0, 0.0, -1.0)}), (1.0, 0.0))


def test_runner_refuses_bad_runs() -> None:
    rng = np.random.default_rng(0)
    with pytest.raises(ValueError, match="n_vehicles"):
        fly_flock_scene(open_hall(), 0, FlockPlannerKind.TRIANGULAR, 10, rng)
    with pytest.raises(ValueError, match="max_steps"):
        fly_flock_scene(open_hall(), 3, FlockPlannerKind.TRIANGULAR, 0, rng)
    hall = open_hall()
    blocked = FlockScene(
        "blocked",
        World(hall.world.room, (Box("crate", (2.0, -1.0, -2.0), (3.6, 1.0, 0.0)),)),
        hall.leader_start_n,
        hall.common_goal_n,
    )
    with pytest.raises(ValueError, match="inside an obstacle"):
        fly_flock_scene(blocked, 5, FlockPlannerKind.TRIANGULAR, 10, rng)


def test_a_run_that_runs_out_of_steps_says_so() -> None:
    r = fly_flock_scene(open_hall(), 3, FlockPlannerKind.TRIANGULAR, 20, np.random.default_rng(0))
    assert not r.reached and r.reason == "vehicles [1, 2, 3] short of their goals"
    assert r.leader_time_s is None
    assert r.track_n.shape == (21, 3, 3)


def test_table_room_leader_ends_under_the_table() -> None:
    scene = table_room()
    r = fly_flock_scene(scene, 5, FlockPlannerKind.TRIANGULAR, 600, np.random.default_rng(0))
    assert r.reached, r.reason
    assert r.collisions == 0
    end = r.paths_n[1][-1]
    top = next(b for b in scene.world.obstacles if b.name == "table-top")
    assert top.min_n[0] < end[0] < top.max_n[0] and top.min_n[1] < end[1] < top.max_n[1]
    assert end[2] > top.max_n[2]  # below the top (z is down)
    assert r.messages_sent > 0 and r.formation_error_m is not None


def test_the_guard_reads_of_teammates_are_counted_once_per_pair_and_step() -> None:
    ids = [11, 12, 13, 14, 15]
    planner = FlockPlanner(ids, FlockMission((10.0, 0.0, -1.0)), (1.0, 0.0))
    pos = planner.start_positions_n((2.0, 0.0, -1.0))
    out = planner.step(0, pos, dict.fromkeys(ids, ProximityReading.clear()))
    # Everyone moves on step 0, and each move's guard read all 4 teammates (position and
    # planned set point): N (N - 1) = 20 pairs, however many candidate moves were tried.
    assert all(out.setpoints_n[v] != pos[v] for v in ids)
    assert out.state_reads == 20 and out.messages_total == 4 + 20


def test_a_team_holding_its_slots_reads_only_the_settled_flags() -> None:
    ids = [11, 12, 13, 14, 15]
    planner = FlockPlanner(ids, FlockMission((2.0, 0.0, -1.0)), (1.0, 0.0))
    pos = planner.start_positions_n((2.0, 0.0, -1.0))
    clear = dict.fromkeys(ids, ProximityReading.clear())
    out = planner.step(0, pos, clear)
    assert out.setpoints_n == pos  # at the goal already: nobody moves, the guard reads nothing
    assert out.state_reads == 4  # each follower looks whether its leader queues on a trail
    out = planner.step(1, pos, clear)
    # The root, at the common goal, asks each of 4 followers whether it settled; 14 and 15
    # ask whether their leader 12 has.
    assert out.setpoints_n == pos and out.state_reads == 4 + 2


def test_run_books_every_message_of_the_flock() -> None:
    r = fly_flock_scene(open_hall(), 5, FlockPlannerKind.TRIANGULAR, 80, np.random.default_rng(0))
    assert r.state_reads > r.messages_sent > 0
    assert r.messages_total == r.messages_sent + r.state_reads
    # all pairs plus eq. 9.1's 4 per plan; the loop plans once more than it moves
    assert r.messages_total <= (r.steps + 1) * (5 * 4 + 4)
    rey = fly_flock_scene(open_hall(), 5, FlockPlannerKind.REYNOLDS, 80, np.random.default_rng(0))
    assert rey.state_reads == 0 and rey.messages_total == (rey.steps + 1) * 5 * 4
