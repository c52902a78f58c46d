"""Triangular formation geometry and binary-tree roles (Definitions 3–5)."""

import itertools

import numpy as np
import pytest

from planners.flocking.formation import (
    Formation,
    FormationParams,
    Role,
    children_of,
    parent_of,
    role_of,
    rotate_f_to_n,
)


@pytest.mark.parametrize("n", [3, 5, 15, 31])
def test_every_triangle_is_equilateral_with_side_i_d(n: int) -> None:
    f = Formation.build(n)
    tris = f.triangles()
    assert len(tris) == (n - 1) // 2
    for a, b, c in tris:
        for p, q in itertools.combinations((a, b, c), 2):
            assert np.linalg.norm(f.offsets_f[p] - f.offsets_f[q]) == pytest.approx(0.8)


@pytest.mark.parametrize("n", [2, 5, 15, 31, 40])
def test_no_two_slots_closer_than_the_side(n: int) -> None:
    o = Formation.build(n).offsets_f
    d = np.linalg.norm(o[:, None] - o[None], axis=2) + np.eye(n) * 1e3
    assert d.min() >= 0.8 - 1e-9


@pytest.mark.parametrize(
    ("n", "relays", "leaves"), [(5, [1], [2, 3, 4]), (15, list(range(1, 7)), list(range(7, 15)))]
)
def test_binary_tree_roles(n: int, relays: list[int], leaves: list[int]) -> None:
    assert role_of(0, n) is Role.LEADER
    assert [i for i in range(n) if role_of(i, n) is Role.RELAY] == relays
    assert [i for i in range(n) if role_of(i, n) is Role.FOLLOWER] == leaves


def test_31_vehicles_form_a_complete_tree_of_depth_4() -> None:
    f = Formation.build(31)
    assert sum(f.role(i) is Role.FOLLOWER for i in range(31)) == 16
    assert sum(f.role(i) is Role.RELAY for i in range(31)) == 14
    assert children_of(14, 31) == (29, 30)
    assert parent_of(30) == 14
    assert parent_of(0) is None


def test_first_triangle_points_back_from_the_leader() -> None:
    f = Formation.build(3)
    off1, off2 = f.offset_from_parent_f(1), f.offset_from_parent_f(2)
    assert off1[0] < 0 and off2[0] < 0  # both behind
    assert off1[1] == pytest.approx(-off2[1])  # symmetric: θ = 30° each side


def test_slot_rotates_with_team_heading() -> None:
    f = Formation.build(3)
    east = np.array([0.0, 1.0])
    slot = f.slot_n(1, np.array([5.0, 5.0]), east)
    # Heading east, "behind" is west (smaller y).
    assert slot[1] < 5.0
    assert np.linalg.norm(slot - np.array([5.0, 5.0])) == pytest.approx(0.8)
    with pytest.raises(ValueError, match="non-zero"):
        rotate_f_to_n(np.ones(2), np.zeros(2))


def test_side_must_exceed_sensing_range() -> None:
    with pytest.raises(ValueError, match="Definition 5"):
        FormationParams(side_m=0.45)
    with pytest.raises(ValueError, match="at least one"):
        Formation.build(0)
