"""Eq. 9.1 open-loop messages: silence while the leader avoids, followers wait, then catch up."""

import numpy as np
import pytest

from planners.flocking.comm import OpenLoopChannel, send_rule
from planners.flocking.planner import FlockMission, FlockParams, FlockPlanner, LeaderAvoider
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


@pytest.mark.parametrize("avoider", list(LeaderAvoider))
def test_followers_wait_while_the_leader_avoids_then_catch_up(avoider: LeaderAvoider) -> None:
    ids = [1, 2, 3]
    params = FlockParams(leader_avoider=avoider)
    planner = FlockPlanner(ids, FlockMission((20.0, 0.0, -1.0)), (1.0, 0.0), params)
    pos = planner.start_positions_n((4.0, 0.0, -1.0))
    clear = ProximityReading.clear()
    step = 0

    def advance(leader_reading: ProximityReading) -> tuple[int, bool]:
        nonlocal step, pos
        out = planner.step(step, pos, {1: leader_reading, 2: clear, 3: clear})
        pos = out.setpoints_n
        step += 1
        return out.messages_sent, out.leader_avoiding

    for _ in range(5):
        assert advance(clear) == (2, False)  # one message to each follower per step
    # A wall ahead of the leader: it avoids, and eq. 9.1 sends nothing while it does.
    f2_track = []
    for _ in range(10):
        sent, avoiding = advance(_wall_ahead(0.32))
        assert avoiding and sent == 0
        f2_track.append(pos[2])
    # The followers went on to the last goal they were given, then waited there.
    assert f2_track[-1] == f2_track[-2] == f2_track[-3]
    assert pos[1][1] != 0.0  # the leader went round sideways
    # The way is free again: messages resume and the followers boost (2 d per step).
    resumed = False
    for _ in range(20):
        sent, avoiding = advance(clear)
        assert (sent == 0) == avoiding
        if sent:
            resumed = True
            break
    assert resumed
    moves = []
    for _ in range(8):
        before = pos[2]
        assert advance(clear)[0] == 2
        moves.append(float(np.linalg.norm(np.subtract(pos[2], before))))
    assert max(moves) == pytest.approx(2 * params.step_m)
