"""The exact-move kinematic world and its collision books."""

import pytest

from planners.geometry import Box, World
from planners.kinematic import KinematicParams, KinematicSim

WORLD = World(
    Box("room", (0.0, 0.0, -3.0), (5.0, 5.0, 0.0)),
    (Box("cube", (2.0, 2.0, -1.0), (3.0, 3.0, 0.0)),),
)


def test_free_move_is_exact_and_clean() -> None:
    sim = KinematicSim(WORLD, (1.0, 1.0, -1.5))
    out = sim.move_to((1.0, 1.5, -1.5))
    assert sim.pos_n == (1.0, 1.5, -1.5)
    assert not out.collided and sim.collisions == 0
    assert sim.path == [(1.0, 1.0, -1.5), (1.0, 1.5, -1.5)]


def test_move_through_box_is_a_penetrating_collision() -> None:
    sim = KinematicSim(WORLD, (1.5, 2.5, -0.5))
    out = sim.move_to((3.5, 2.5, -0.5))
    assert out.collided and out.penetrated
    assert sim.collisions == 1 and sim.penetrations == 1
    assert sim.min_clearance_m == 0.0


def test_grazing_within_body_radius_collides_without_penetrating() -> None:
    sim = KinematicSim(WORLD, (1.0, 1.9, -0.5), KinematicParams(body_radius_m=0.15))
    out = sim.move_to((2.5, 1.9, -0.5))
    assert out.collided and not out.penetrated
    assert out.clearance_m == pytest.approx(0.1)


def test_leaving_the_room_penetrates() -> None:
    sim = KinematicSim(WORLD, (0.5, 0.5, -1.0))
    assert sim.move_to((-0.5, 0.5, -1.0)).penetrated


def test_sense_uses_current_position() -> None:
    sim = KinematicSim(WORLD, (1.0, 2.5, -0.5))
    assert sim.sense().front_m is None
    sim.move_to((1.7, 2.5, -0.5))
    assert sim.sense().front_m == pytest.approx(0.3)
