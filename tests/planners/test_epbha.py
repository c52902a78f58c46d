"""EPBHA: subfunctions, obstacle classes and the thesis's scenes in the kinematic world."""

import math

import pytest

from gcs.mission.kinematic_runs import START_BLOCKED, fly_epbha_scene
from gcs.mission.report import MissionStatus
from planners.epbha.planner import (
    Epbha,
    EpbhaParams,
    Move,
    ObstacleClass,
    Plane,
    Reason,
    Status,
)
from planners.proximity import Facing, ProximityReading
from planners.scenes import Scene, thesis_scenes

START = (0.0, 0.0, -1.0)


def reading(**facings: float) -> ProximityReading:
    return ProximityReading.from_facings({Facing[k.upper()]: v for k, v in facings.items()})


def planner(goal: tuple[float, float, float] = (2.0, 0.0, -1.0)) -> Epbha:
    return Epbha(EpbhaParams(), goal, START)


def test_params_reject_a_blocked_distance_beyond_sensor_range() -> None:
    with pytest.raises(ValueError, match="sensor range"):
        EpbhaParams(step_m=0.2, keep_off_m=0.35)


def test_cost_is_weighted_manhattan_distance_to_plane_goal() -> None:
    p = planner((1.0, 0.5, -0.2))
    assert p.cost((0.0, 0.0, -1.0)) == pytest.approx(4.0 * 1.0 + 2.0 * 0.5)
    p.plane = Plane.YZ
    assert p.cost((0.0, 0.0, -1.0)) == pytest.approx(4.0 * 0.5 + 2.0 * 0.8)


def test_grid_making_gives_four_in_plane_neighbours() -> None:
    p = planner()
    assert set(p.grid_moves()) == {Move.NORTH, Move.SOUTH, Move.EAST, Move.WEST}
    p.plane = Plane.YZ
    assert set(p.grid_moves()) == {Move.EAST, Move.WEST, Move.DOWN, Move.UP}


def test_heading_uses_the_larger_absolute_displacement() -> None:
    # The thesis's signed comparison would call a southward move a y heading.
    assert Epbha.heading_of((1.0, 0.0, 0.0), (0.9, 0.02, 0.0)) is Move.SOUTH
    assert Epbha.heading_of((0.0, 0.0, 0.0), (0.0, -0.1, 0.0)) is Move.WEST
    assert Epbha.heading_of((0.0, 0.0, 0.0), (0.0, 0.0, 0.0)) is None


def test_sensor_values_reorient_with_yaw() -> None:
    # Facing east, the sensor seeing north is the left one.
    r = ProximityReading.from_facings({Facing.LEFT: 0.2}, yaw_rad=math.pi / 2)
    assert r.along_n(Move.NORTH.vec()) == 0.2
    assert r.along_n(Move.EAST.vec()) is None


def test_movement_options_count_sensors_that_see_nothing() -> None:
    assert planner().movement_options(reading(front=0.3, up=0.45, down=0.6)) == 4


def test_next_set_position_steps_toward_the_goal_side() -> None:
    p = planner((2.0, -1.0, -1.0))
    assert p.lateral_toward_goal(START, Move.NORTH, ProximityReading.clear()) is Move.WEST
    p = planner((2.0, 0.0, -1.0))
    # Goal dead ahead: the side that sees farther.
    assert p.lateral_toward_goal(START, Move.NORTH, reading(right=0.4)) is Move.WEST
    assert p.lateral_toward_goal(START, Move.NORTH, reading(left=0.3, right=0.45)) is Move.EAST


def test_free_space_moves_to_minimum_cost_with_four_evaluations() -> None:
    p = planner((1.0, 1.0, -1.0))
    d = p.step(START, ProximityReading.clear())
    assert d.status is Status.MOVING and d.reason is Reason.COST
    assert d.next_pos_n == pytest.approx((0.1, 0.0, -1.0))  # A > B: forward before sideways
    assert d.cost_evaluations == 4 and len(d.costs) == 4
    assert min(d.costs, key=lambda e: e.cost).move is Move.NORTH


def test_single_sided_obstacle_goes_around_without_cost_evaluations() -> None:
    p = planner((2.0, 0.0, -1.0))
    d = p.step(START, reading(front=0.25))
    assert d.obstacle is ObstacleClass.SINGLE_SIDED and d.reason is Reason.GO_AROUND
    assert d.next_pos_n == pytest.approx((0.0, 0.1, -1.0))  # goal dead ahead: the open side
    d2 = p.step(d.next_pos_n, reading(front=0.26))
    assert d2.reason is Reason.GO_AROUND and d2.cost_evaluations == 0


def test_partition_is_passed_over() -> None:
    p = planner()
    d = p.step(START, reading(front=0.25, right=0.35))
    assert d.obstacle is ObstacleClass.PARTITION and d.reason is Reason.PASS_OVER
    assert d.next_pos_n == pytest.approx((0.0, 0.0, -1.1))  # up is -z


def test_lateral_view_of_the_same_wall_is_not_a_partition() -> None:
    # A wall 0.2 m ahead shows in a side cone no nearer than 0.2 / sin(22.5°) = 0.52 m.
    p = planner()
    single = p.classify(reading(front=0.2, right=0.49), Move.NORTH, START)
    assert single is ObstacleClass.SINGLE_SIDED
    # A wall 0.3 m ahead cannot show in a side cone within range: that is a wing.
    assert p.classify(reading(front=0.3, right=0.49), Move.NORTH, START) is ObstacleClass.PARTITION


def test_cave_backs_off_diagonally_as_a_staircase() -> None:
    p = planner()
    d1 = p.step(START, reading(front=0.25, up=0.3))
    assert d1.obstacle is ObstacleClass.CAVE and d1.reason is Reason.BACK_OFF
    assert d1.next_pos_n == pytest.approx((-0.1, 0.0, -1.0))
    d2 = p.step(d1.next_pos_n, reading(up=0.3))
    assert d2.reason is Reason.BACK_OFF
    assert d2.next_pos_n == pytest.approx((-0.1, 0.1, -1.0))  # then sideways


def test_cave_with_everything_closed_is_a_deadlock_and_hovers() -> None:
    p = planner()
    d = p.step(START, reading(front=0.25, back=0.25, left=0.25, right=0.25, up=0.3))
    assert d.status is Status.DEADLOCK and d.reason is Reason.DEADLOCK_BLOCKED
    assert d.next_pos_n == pytest.approx(START)


def test_keep_off_backs_away_from_a_near_obstacle() -> None:
    d = planner().step(START, reading(up=0.1))
    assert d.reason is Reason.KEEP_OFF
    assert d.next_pos_n == pytest.approx((0.0, 0.0, -0.9))


def test_a_vertical_keep_off_lets_a_hold_a_little_high_fly_on_under_a_table() -> None:
    # under a table top 0.24 m above the sensors, the floor 0.48 m below: the thesis's one
    # offset steps down toward whatever is below; the flat body's vertical offset flies on
    under_table = reading(up=0.24, down=0.48)
    assert planner().step(START, under_table).reason is Reason.KEEP_OFF
    p = Epbha(EpbhaParams(keep_off_vertical_m=0.15), (2.0, 0.0, -1.0), START)
    d = p.step(START, under_table)
    assert d.reason is Reason.COST and d.next_pos_n == pytest.approx((0.1, 0.0, -1.0))
    # nearer than the vertical offset it still backs away, and sideways the radius counts
    p = Epbha(EpbhaParams(keep_off_vertical_m=0.15), (2.0, 0.0, -1.0), START)
    d = p.step(START, reading(up=0.12, down=0.48))
    assert d.reason is Reason.KEEP_OFF and d.next_pos_n == pytest.approx((0.0, 0.0, -0.9))
    p = Epbha(EpbhaParams(keep_off_vertical_m=0.15), (2.0, 0.0, -1.0), START)
    assert p.step(START, reading(front=0.2)).reason is Reason.KEEP_OFF


def test_a_vertical_swept_clearance_scales_vertical_offsets() -> None:
    assert EpbhaParams().swept_z_scale == 1.0
    assert EpbhaParams(swept_clearance_vertical_m=0.085).swept_z_scale == pytest.approx(2.0)
    with pytest.raises(ValueError, match="swept_clearance_vertical_m"):
        EpbhaParams(swept_clearance_vertical_m=0.0)


def test_a_vertical_keep_off_beyond_the_sensor_range_is_refused() -> None:
    with pytest.raises(ValueError, match="keep_off_vertical_m"):
        EpbhaParams(keep_off_vertical_m=0.45)
    with pytest.raises(ValueError, match="keep_off_vertical_m"):
        EpbhaParams(keep_off_vertical_m=-0.1)


def test_xy_goal_then_yz_goal_then_reached() -> None:
    p = planner((0.0, 0.0, -0.8))
    d = p.step(START, ProximityReading.clear())
    assert d.plane is Plane.YZ and d.next_pos_n == pytest.approx((0.0, 0.0, -0.9))
    d = p.step(d.next_pos_n, ProximityReading.clear())
    d = p.step(d.next_pos_n, ProximityReading.clear())
    assert d.status is Status.REACHED and d.next_pos_n == pytest.approx((0.0, 0.0, -0.8))


def test_revisiting_a_cell_too_often_is_a_loop_deadlock() -> None:
    p = Epbha(EpbhaParams(max_visits=2), (2.0, 0.0, -1.0), START)
    for _ in range(2):
        assert p.step(START, reading(up=0.2, down=0.2)).status is Status.MOVING
    d = p.step(START, reading(up=0.2, down=0.2))
    assert d.status is Status.DEADLOCK and d.reason is Reason.DEADLOCK_LOOP


@pytest.mark.parametrize("scene", thesis_scenes(), ids=lambda s: s.name)
def test_thesis_scenes_are_reached_without_collisions(scene: Scene) -> None:
    r = fly_epbha_scene(scene.world, scene.start_n, scene.goal_n, max_steps=1500)
    assert r.reached, r.detail
    assert r.collisions == 0 and r.min_clearance_m >= 0.15
    assert math.dist(r.path[-1], scene.goal_n) <= 0.1
    assert r.cost_evaluations <= 4 * r.steps
    assert len(r.cpu_s_per_step) == r.steps + 1


def test_after_keeping_off_it_does_not_step_straight_back() -> None:
    p = planner()
    d1 = p.step(START, reading(front=0.2))
    assert d1.reason is Reason.KEEP_OFF and d1.next_pos_n == pytest.approx((-0.1, 0.0, -1.0))
    # Back at 0.3 m the front is formally free, but it has just recoiled from it.
    d2 = p.step(d1.next_pos_n, reading(front=0.36))
    assert d2.reason is Reason.GO_AROUND and d2.obstacle is ObstacleClass.SINGLE_SIDED


def test_overhead_seen_with_a_wing_is_a_cave() -> None:
    d = planner().step(START, reading(front=0.3, right=0.4, up=0.45))
    assert d.obstacle is ObstacleClass.CAVE and d.reason is Reason.BACK_OFF


def test_partition_whose_climb_is_blocked_goes_around_instead() -> None:
    p = planner()
    d = p.step(START, reading(front=0.3, right=0.4))
    assert d.reason is Reason.PASS_OVER
    d = p.step(d.next_pos_n, reading(front=0.3, right=0.4, up=0.33))
    # Goal dead ahead and the right side has a wing: around on the left (west, -y).
    assert d.reason is Reason.GO_AROUND and d.next_pos_n[1] < 0.0


def test_pass_along_reaches_the_face_that_blocked_the_way() -> None:
    # Descending onto a table top 0.3 m below: step aside until the down cone is clear, then
    # keep descending at least 0.3 m + body radius even where no side cone sees the table.
    p = Epbha(EpbhaParams(), (0.0, 0.0, -0.2), START)
    p.plane = Plane.YZ
    pos = START
    d = p.step(pos, reading(down=0.3))
    assert d.reason is Reason.GO_AROUND
    while d.reason is Reason.GO_AROUND:
        pos = d.next_pos_n
        d = p.step(pos, reading(down=0.3) if pos[1] < 0.25 else ProximityReading.clear())
    descended = 0
    while d.reason is Reason.PASS_ALONG:
        descended += 1
        d = p.step(d.next_pos_n, ProximityReading.clear())
    assert descended * 0.1 >= 0.3 + 0.17 - 1e-9


def test_the_epbha_loop_reports_a_deadlock_in_a_closed_cell() -> None:
    from planners.geometry import Box, World

    room = Box("room", (0.0, 0.0, -2.0), (3.0, 3.0, 0.0))
    cell = World(room, (
        Box("n", (1.7, 1.0, -2.0), (1.8, 2.0, 0.0)),
        Box("s", (1.2, 1.0, -2.0), (1.3, 2.0, 0.0)),
        Box("e", (1.2, 1.7, -2.0), (1.8, 1.8, 0.0)),
        Box("w", (1.2, 1.2, -2.0), (1.8, 1.3, 0.0)),
        Box("lid", (1.2, 1.2, -1.8), (1.8, 1.8, -1.7)),
    ))
    r = fly_epbha_scene(cell, (1.5, 1.5, -1.0), (2.5, 1.5, -1.0), max_steps=500)
    assert r.status is MissionStatus.FAILED and r.reason.startswith("deadlock")
    assert r.penetrations == 0 and r.collisions == 0


def test_the_epbha_loop_stops_at_max_steps() -> None:
    scene = thesis_scenes()[0]
    r = fly_epbha_scene(scene.world, scene.start_n, scene.goal_n, max_steps=5)
    assert r.reason == "no goal within 5 steps" and r.steps == 5


def test_noisy_sensors_still_reach_the_thesis_scenes() -> None:
    import numpy as np

    from planners.proximity import ProximityParams

    for scene in thesis_scenes():
        r = fly_epbha_scene(scene.world, scene.start_n, scene.goal_n,
                      proximity=ProximityParams(noise_sigma_m=0.01),
                      rng=np.random.default_rng(7))
        assert r.reached and r.collisions == 0, scene.name


def test_the_epbha_loop_refuses_a_start_inside_an_obstacle() -> None:
    scene = thesis_scenes()[0]
    inside_table = (3.5, 2.0, -0.78)
    r = fly_epbha_scene(scene.world, inside_table, scene.goal_n)
    assert r.reason == START_BLOCKED and len(r.path) == 1


def test_ceiling_high_wall_is_gone_around_below_the_maximum_altitude() -> None:
    from planners.geometry import Box, World

    room = Box("room", (0.0, 0.0, -2.5), (5.0, 3.0, 0.0))
    # A wall to the ceiling with a wing: climbing is useless, the way is around its east end.
    world = World(room, (
        Box("wall", (2.5, 0.0, -2.5), (2.55, 2.2, 0.0)),
        Box("wing", (1.9, 0.8, -2.5), (2.55, 0.85, 0.0)),
    ))
    params = EpbhaParams(max_alt_m=1.6)
    r = fly_epbha_scene(world, (0.5, 1.2, -1.0), (4.5, 1.2, -1.0), params, max_steps=800)
    assert r.reached and r.collisions == 0
    assert max(-p[2] for p in r.path) <= 1.6 + 1e-9
    assert max(p[1] for p in r.path) > 2.2  # went around the east end
