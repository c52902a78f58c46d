"""EPBHA on the bundled SITL: the table scene flown by the station, checked against truth."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from gcs.mission import recording as topics
from logs import open_recording

MISSION = Path(__file__).resolve().parents[2] / "missions" / "epbha_table.toml"


@pytest.mark.e2e
@pytest.mark.timeout(240)
@pytest.mark.xfail(strict=False, reason=(
    "#32: flown under the table top at 0.45 m on the SITL's 3.2.1 analog sonar (6 cm steps, "
    "nothing used below 20 cm), the station's hold is 7-10 cm RMS; at 2x on a loaded 2-core "
    "machine one flight in three touched (the lockstep seeds in test_mission_one_loop and "
    "test_mission_lockstep stay clear)"))
def test_epbha_table_on_the_sitl_reaches_the_box_without_collisions(tmp_path: Path) -> None:
    # a fresh process, as a user runs it: the station's loop shares nothing with other tests
    proc = subprocess.run(
        [sys.executable, "-m", "gcs", "mission", "run", str(MISSION), "--speedup", "2",
         "--seed", "3", "--json", "-o", str(tmp_path)],
        capture_output=True, text=True, timeout=200, check=False)
    out = proc.stdout.strip().splitlines()
    assert out, f"exit {proc.returncode}: {proc.stderr.strip()}"
    d = json.loads(out[-1])
    assert proc.returncode == 0, d
    assert d["status"] == "reached" and d["mode"] == "vehicle"
    # collisions of the airframe's contact body with the world's boxes, from SITL ground truth
    assert d["collision_source"] == "truth" and d["truth_samples"] > 500
    assert d["collisions"] == 0 and d["truth_min_clearance_m"] > 0.0
    assert d["goal_error_m"] <= 0.15
    rec = open_recording(d["recording"])
    steps = [m for _, _, m in rec.messages([topics.STEP_EPBHA])]
    assert len(steps) == d["steps"] + 1
    assert steps[-1]["decision"]["status"] == "reached"
    # readings came from the companion board's six sensors: the table top seen from under it
    assert any(s["reading"]["up"] is not None for s in steps)
    assert rec.counts["/vehicle/proximity"] > 100 and rec.counts["/gcs/rc_override"] > 500
    assert rec.counts[topics.SCENE] == 1 and rec.counts[topics.SUMMARY] == 1
