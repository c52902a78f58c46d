"""Through a one-vehicle door the team passes one by one, in different altitude layers."""

import numpy as np
import pytest

from gcs.mission.kinematic_flock import fly_flock_scene
from planners.flocking.planner import FlockParams
from planners.flocking.scenes import narrow_opening
from planners.flocking.swarm import FlockPlannerKind


@pytest.fixture(scope="module")
def door_run():
    scene = narrow_opening()
    rng = np.random.default_rng(3)
    return scene, fly_flock_scene(scene, 5, FlockPlannerKind.TRIANGULAR, 600, rng)


def test_door_is_passed_without_collision_and_above_the_safe_distance(door_run) -> None:
    _, r = door_run
    assert r.reached, r.reason
    assert r.collisions == 0
    assert r.min_separation_m >= FlockParams().formation.safe_distance_m - 1e-9


def test_one_vehicle_per_layer_in_the_doorway(door_run) -> None:
    scene, r = door_run
    gate = scene.gate
    assert gate is not None
    assert len(r.gate_crossings_s) == 5
    x = r.track_n[:, :, 0]  # (steps, vehicles)
    in_door = (x >= 10.0) & (x <= gate.x_n)
    spacing = FlockParams().layer_spacing_m
    for t in range(len(x)):
        inside = np.flatnonzero(in_door[t])
        z = r.track_n[t, inside, 2]
        # One per layer: vehicles sharing the doorway are stacked, never side by side.
        for i in range(len(inside)):
            for j in range(i + 1, len(inside)):
                assert abs(z[i] - z[j]) >= spacing - 1e-9
    assert in_door.sum(axis=1).max() <= FlockParams().n_layers
    assert r.throughput_vps is not None and r.throughput_vps > 0.0


def test_followers_change_layer_to_pass(door_run) -> None:
    scene, r = door_run
    gate = scene.gate
    assert gate is not None
    alts = []
    for v in sorted(r.paths_n):
        p = r.paths_n[v]
        k = int(np.argmax(p[:, 0] >= gate.x_n))
        alts.append(round(-float(p[k, 2]), 2))
    cruise = -scene.common_goal_n[2]
    assert alts[0] == pytest.approx(cruise)  # the leader keeps cruise altitude
    assert len(set(alts)) >= 2  # followers crossed in other layers
    assert max(abs(a - cruise) for a in alts) == pytest.approx(FlockParams().layer_spacing_m)
