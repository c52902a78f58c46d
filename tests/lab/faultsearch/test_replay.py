"""`quadgcs fly --lockstep --seed N --faults FILE` replays a run bit for bit: the same seed and
schedule give the same recording (every message of every topic) and the same summary; the
schedule is flown (the recording differs without it)."""

from __future__ import annotations

from pathlib import Path

from bench.recording_hashes import fly

SCHEDULE = """
[[fault]]
kind = "loss_both"
start = "takeoff+0.5"
length = 2.0
size = 0.3

[[fault]]
kind = "sonar_late"
start = "hold+0.2"
length = 1.0
size = 0.4

[[fault]]
kind = "imu_spike"
start = 14.0
length = 0.3
size = 6.0
"""


def test_the_same_seed_and_schedule_fly_the_same_recording(tmp_path: Path) -> None:
    faults = tmp_path / "faults.toml"
    faults.write_text(SCHEDULE, encoding="utf-8")
    args = ["fly", "--lockstep", "--seed", "4", "--alt", "1.0", "--hold", "2"]
    first = fly("first", [*args, "--faults", str(faults)], tmp_path)
    again = fly("again", [*args, "--faults", str(faults)], tmp_path)
    clean = fly("clean", args, tmp_path)
    assert first["exit"] == again["exit"] == clean["exit"] == 0
    assert len(first["topics"]) > 5
    assert first == again
    assert first["topics"] != clean["topics"]
