"""The replay player on a simulated clock: timing, pause, seek, speed, and the headless run."""

from __future__ import annotations

import io

import pytest

from gcs.cli import main
from logs import Recorder, RecordingError, open_recording
from logs.replay import Player, run_headless


class SimClock:
    """A clock that moves only when told; `sleep` advances it."""

    def __init__(self) -> None:
        self.now = 1000.0
        self.slept: list[float] = []

    def __call__(self) -> float:
        return self.now

    def sleep(self, dt_s: float) -> None:
        self.slept.append(dt_s)
        self.now += dt_s


@pytest.fixture
def ten_hz(tmp_path):
    """A 10 Hz counter over 5 s (t = 0.0 … 4.9 s), plus one alt estimate per message."""
    with Recorder(tmp_path / "p.mcap", metadata={}, anchor_ns=0) as rec:
        for i in range(50):
            t = 50.0 + i * 0.1
            rec.put("/count", t, {"i": i})
            rec.put("/gcs/estimate", t, {"alt_m": i * 0.02})
    return open_recording(rec.path)


def test_messages_come_when_their_time_has_come(ten_hz) -> None:
    clock = SimClock()
    player = Player(ten_hz, topics=["/count"], clock=clock)
    assert [m.message["i"] for m in player.due()] == [0]  # what the start position shows
    clock.now += 5.0
    assert player.due() == []  # not playing yet: the position holds
    player.play()
    clock.now += 0.25
    assert [m.message["i"] for m in player.due()] == [1, 2]
    assert player.wait_s() == pytest.approx(0.05)


def test_pause_holds_and_resume_continues(ten_hz) -> None:
    clock = SimClock()
    player = Player(ten_hz, topics=["/count"], clock=clock)
    player.play()
    clock.now += 1.0
    player.due()
    player.pause()
    clock.now += 10.0
    assert player.due() == []
    assert player.position_s == pytest.approx(1.0)
    assert player.wait_s() == float("inf")
    player.play()
    clock.now += 0.1
    assert [m.message["i"] for m in player.due()] == [11]


def test_seek_and_speed(ten_hz) -> None:
    clock = SimClock()
    player = Player(ten_hz, topics=["/count"], clock=clock)
    player.seek(3.0)
    player.play()
    assert [m.message["i"] for m in player.due()] == [30]
    player.speed = 4.0
    clock.now += 0.25  # one recorded second at 4x
    assert [m.message["i"] for m in player.due()] == list(range(31, 41))
    player.seek(0.0)
    assert [m.message["i"] for m in player.due()] == [0]
    player.seek(99.0)
    player.due()
    assert player.finished
    with pytest.raises(RecordingError, match="speed"):
        player.speed = 0.0


def test_headless_run_prints_a_line_per_recorded_second(ten_hz) -> None:
    clock = SimClock()
    out = io.StringIO()
    report = run_headless(Player(ten_hz, clock=clock), out, sleep=clock.sleep)
    lines = out.getvalue().splitlines()
    assert report.messages == 101  # 50 counts, 50 estimates, the display transform
    assert len(lines) == 5  # t = 1, 2, 3, 4 and the end at 4.9 s
    assert "alt est   0.18 m" in lines[0]  # the estimate at 0.9 s, the last before t = 1 s
    assert clock.now - 1000.0 == pytest.approx(4.9, abs=0.01)  # real-time pacing
    assert max(clock.slept) <= 0.25


def test_headless_at_double_speed_takes_half_the_time(ten_hz) -> None:
    clock = SimClock()
    run_headless(Player(ten_hz, clock=clock, speed=2.0), io.StringIO(), sleep=clock.sleep)
    assert clock.now - 1000.0 == pytest.approx(2.45, abs=0.01)


def test_replay_cli_max(recorded_flight, capsys) -> None:
    path, counts = recorded_flight
    assert main(["replay", str(path), "--max"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[-1] == f"replayed {sum(counts.values())} messages, 6.0 s of flight"
    assert "mode ALT_HOLD" in out[-2]
    assert len(out) == 5 + 1 + 1  # t = 1…5 s, the end at 5.98 s, the summary
