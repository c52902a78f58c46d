"""Eq. 9.1 open-loop messages: silence while the leader avoids, followers wait, then catch up."""

import numpy as np
import pytest

from planners.flock_comm import OpenLoopChannel, send_rule
from planners.flocking import FlockMission, FlockParams, FlockPlanner, VehicleMode
from planners.proximity import ProximityReading


def test_send_rule_is_eq_9_1() -> None:
    assert send_rule(avoiding_obstacle=False) is True
    assert send_rule(avoiding_obstacle=True) is False


def test_channel_counts_one_message_per_follower_and_withholds_when_avoiding() -> None:
    ch = OpenLoopChannel(latency_steps=1)
    assert ch.offer(0, 0, (1, 2), (1.0, 0.0, -1.0), avoiding_obstacle=False) == 2
    assert ch.offer(1, 0, (1, 2), (1.1, 0.0, -1.0), avoiding_obstacle=True) == 0
    assert ch.messages_sent == 2 and ch.sends_withheld == 1
    assert ch.deliver(0, 1) == []  # one step of latency
    (msg,) = ch.deliver(1, 1)
    assert msg.pos_n == (1.0, 0.0, -1.0) and msg.sender == 0
    with pytest.raises(ValueError, match="latency"):
        OpenLoopChannel(latency_steps=-1)


def _wall_ahead(front_m: float) -> ProximityReading:
    return ProximityReading(front_m, None, None, None, None, None)


def test_followers_wait_while_the_leader_avoids_then_catch_up() -> None:
    ids = [1, 2, 3]
    planner = FlockPlanner(ids, FlockMission((20.0, 0.0, -1.0)), (1.0, 0.0))
    pos = planner.start_positions_n((4.0, 0.0, -1.0))
    clear = ProximityReading.clear()
    step = 0

    def advance(leader_reading: ProximityReading) -> int:
        nonlocal step, pos
        out = planner.step(step, pos, {1: leader_reading, 2: clear, 3: clear})
        pos = out.setpoints_n
        step += 1
        return out.messages_sent

    for _ in range(5):
        assert advance(clear) == 2  # one message to each follower per step
    # The leader meets an obstacle: it sidesteps, sends nothing, the followers stop at the
    # last goal they were given.
    silent = [advance(_wall_ahead(0.32)) for _ in range(6)]
    assert silent == [0] * 6
    f2_before = pos[2]
    assert advance(_wall_ahead(0.32)) == 0
    assert pos[2] == f2_before
    out = planner.step(step, pos, {1: _wall_ahead(0.32), 2: clear, 3: clear})
    assert out.modes[2] is VehicleMode.WAITING and out.leader_avoiding
    # Free again: messages resume and the followers boost (2 d per step) to their new slots.
    leader_y = pos[1][1]
    assert leader_y != 0.0  # it sidestepped
    # The sidestep overshoots its corner by two steps, still silent.
    overshoot = [advance(clear) for _ in range(FlockParams().sidestep_overshoot_steps)]
    assert overshoot == [0] * FlockParams().sidestep_overshoot_steps
    moves = []
    for _ in range(8):
        before = pos[2]
        assert advance(clear) == 2
        moves.append(float(np.linalg.norm(np.subtract(pos[2], before))))
    assert max(moves) == pytest.approx(2 * FlockParams().step_m)
