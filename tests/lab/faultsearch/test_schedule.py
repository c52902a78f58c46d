"""Fault schedule files: one parser, one line per problem naming the file and the key, and a
file written back reads as the same faults."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from gcs.flight_plan import FlightPlan
from lab.faultsearch.schedule import (
    KINDS,
    Fault,
    Schedule,
    ScheduleError,
    dumps,
    flight_span_s,
    load_schedule,
)

ROOT = Path(__file__).resolve().parents[3]


def _file(tmp_path: Path, body: str) -> Path:
    p = tmp_path / "faults.toml"
    p.write_text(body, encoding="utf-8")
    return p


@pytest.mark.parametrize(("body", "key", "expected"), [
    ('[[fault]]\nkind = "fade_sideways"\nstart = 3\nlength = 1\n', "fault[0].kind",
     "expected one of fade_down"),
    ('[[fault]]\nkind = "stall"\nstart = 900\nlength = 1\n', "fault[0].start",
     "past the flight"),
    ('[[fault]]\nkind = "fade_up"\nstart = "hold+1"\nlength = 1\n[[fault]]\nkind = "stall"\n'
     'start = 3\nlength = -1\n', "fault[1].length", "expected seconds in 0..60"),
    ('[[fault]]\nkind = "fade_up"\nstart = "cruise+1"\nlength = 1\n', "fault[0].start",
     "PHASE one of takeoff, hold, step, landing, mode"),
    ('[[fault]]\nkind = "loss_up"\nstart = 3\nlength = 1\nsize = 2\n', "fault[0].size",
     "expected probability in 0.05..0.95"),
    ('[[fault]]\nkind = "stall"\nstart = 3\n', "fault[0].length", "expected seconds > 0"),
    ('[[fault]]\nkind = "stall"\nstart = 3\nlength = 1\nwhen = 2\n', "fault[0].when",
     "unknown key"),
    ('faults = 3\n', "faults", "unknown key"),
])
def test_a_bad_schedule_is_one_line_naming_the_file_and_the_key(
        tmp_path: Path, body: str, key: str, expected: str) -> None:
    path = _file(tmp_path, body)
    with pytest.raises(ScheduleError) as info:
        load_schedule(path, flight_span_s(FlightPlan(hold_s=2.0)))
    text = str(info.value)
    assert "\n" not in text
    assert text.startswith(f"{path}: {key}")
    assert expected in text


def test_every_kind_writes_back_to_the_same_faults(tmp_path: Path) -> None:
    faults = []
    for i, (name, k) in enumerate(KINDS.items()):
        size = (k.lo + k.hi) / 3.0 if k.size else 0.0
        faults.append(Fault(name, 0.1 * i + 1 / 3, None if i % 2 else "hold",
                            0.0 if k.event else 0.25 + i / 7, size))
    schedule = Schedule(tuple(faults))
    assert load_schedule(_file(tmp_path, dumps(schedule, "a header\nof two lines"))) == schedule


def test_fly_refuses_a_bad_schedule_in_one_line_before_flying(tmp_path: Path) -> None:
    path = _file(tmp_path, '[[fault]]\nkind = "fade_up"\nstart = 2\nlength = -0.5\n')
    done = subprocess.run([sys.executable, "-m", "lab", "fly", "--lockstep", "--hold", "2",
                           "--faults", str(path), "--no-record"], cwd=ROOT, capture_output=True,
                          text=True, timeout=120, check=False)
    assert done.returncode == 2
    assert done.stderr.strip().splitlines() == [
        f"quadgcs fly: {path}: fault[0].length: expected seconds in 0..60, got -0.5"]
