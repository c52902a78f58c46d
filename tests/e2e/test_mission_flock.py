"""Five vehicles of the flock mission on the bundled SITL at 2x: up together, armed together,
off together, every vehicle at its goal, checked against truth, every recording whole."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from gcs.mission import recording as topics
from gcs.mission.events import EVENT
from logs import Recording, open_recording

MISSION = Path(__file__).resolve().parents[2] / "missions" / "flock_table.toml"
HEARTBEAT_S = 1.0  # the vehicle's HEARTBEAT period
AUTO_DISARM_S = 15.0  # ArduCopter 3.2.1 (the mission's profile) on the floor at minimum throttle


def _states(rec: Recording) -> dict[str, float]:
    """Station time of each supervisor state's first entry."""
    first: dict[str, float] = {}
    for _, _, m in rec.messages(["/gcs/supervisor"]):
        first.setdefault(m["state"], m["t_s"])
    return first


@pytest.mark.e2e
@pytest.mark.solo
@pytest.mark.timeout(420)
@pytest.mark.xfail(strict=False, reason=(
    "#32: on the SITL's 3.2.1 analog sonar (6 cm steps, readings under its 20 cm minimum still "
    "sent) an apm25 estimate over the table can diverge: vehicle 1 read -0.86 m against motion "
    "capture's 0.68 m at 2x, and the mission stops on the disagreement as it should"))
def test_five_vehicles_fly_the_flock_to_its_goals_at_2x(tmp_path: Path) -> None:
    # a fresh process, as a user runs it: the station's loops share nothing with other tests
    proc = subprocess.run(
        [sys.executable, "-m", "gcs", "mission", "run", str(MISSION), "--speedup", "2",
         "--seed", "3", "--json", "-o", str(tmp_path)],
        capture_output=True, text=True, timeout=400, check=False)
    out = proc.stdout.strip().splitlines()
    assert out, f"exit {proc.returncode}: {proc.stderr.strip()}"
    d = json.loads(out[-1])
    assert proc.returncode == 0, d
    assert d["status"] == "reached" and d["mode"] == "vehicle" and d["vehicles"] == 5
    assert all(t is not None for t in d["time_to_goal_s"].values())
    # bodies against the world's boxes from the SITL's ground truth, take-off to landing
    assert d["collision_source"] == "truth" and d["truth_samples"] > 5000
    assert d["collisions"] == 0 and d["touched"] == []
    assert len(d["recordings"]) == 5
    took_off: list[float] = []
    armed: list[float] = []
    for path in d["recordings"]:
        rec = open_recording(path)  # raises on a truncated file: every one was closed
        first = _states(rec)
        # the whole flight: pre-flight, armed, take-off, PC hold, LAND, disarmed
        assert {"arming", "manual", "takeoff", "hold", "vehicle", "disarmed"} <= set(first)
        assert first["takeoff"] - first["manual"] < AUTO_DISARM_S - 5.0
        armed.append(first["manual"])
        took_off.append(first["takeoff"])
        assert rec.counts["/gcs/rc_override"] > 2000 and rec.counts["/vehicle/heartbeat"] > 50
        assert rec.counts["/mavlink/rx"] > 10_000 and rec.counts["/mavlink/tx"] > 1000
        assert rec.counts["/gcs/tick"] > 2000
    # armed and off the floor together: within one heartbeat of each other. A station sees its
    # vehicle armed only in the 1 Hz HEARTBEAT, and five stations' ARMs, sent on five loops'
    # own ticks, can fall either side of one (a fresh-clone CI run: 0.02 s apart for three
    # vehicles, a heartbeat later for two)
    assert max(armed) - min(armed) < HEARTBEAT_S + 0.5, armed
    assert max(took_off) - min(took_off) < HEARTBEAT_S + 0.5, took_off
    team = open_recording(d["recording"])
    steps = [m for _, _, m in team.messages([topics.STEP_FLOCK])]
    assert len(steps) == d["steps"] + 1 and team.counts[topics.SUMMARY] == 1
    events = [m["event"] for _, _, m in team.messages([EVENT])]
    assert events[:5] == ["session_ready", "arming", "armed", "taking_off", "airborne"]
    assert events.count("landed") == 5


FADE_AT_S = 80.0  # simulated time: the team is in formation on its way to the common goal


@pytest.mark.e2e
@pytest.mark.timeout(300)
@pytest.mark.xfail(strict=True, raises=AssertionError, reason=(
    "#32: missions fly the direct-throttle hold, which is not safe blind: seed 3's vehicle 3 "
    "flies its last override 5 s before 3.2.1's GCS failsafe and meets its LAND moving at "
    "1.37 m/s (bound 1.0); the climb-rate hold, not yet the missions' default, holds there "
    "(bench/fault_suite.py --hold-mode climb-rate)"))
def test_one_vehicles_radio_fade_ends_the_mission_safely_for_all_five(tmp_path: Path) -> None:
    # lockstep: the five stations and the SITL on one simulated clock, vehicle 3's radio
    # dead both ways for 10 s; the mission stops, the others land, vehicle 3's own failsafe
    # lands it, and nobody relaunches it when its link comes back. The vehicles are 3.2.1s
    # with no GPS fix (indoors): the GCS failsafe lands them (with a fix the pre-flight refuses
    # RTL_ALT 1500, tests/e2e/test_preflight_failsafe.py)
    from gcs.mission.options import RunOptions
    from gcs.mission.runner import run_mission
    from gcs.mission.spec import load_mission

    fade = {"fade": "both", "fade_start_s": FADE_AT_S, "fade_s": 10.0, "vehicles": [3]}
    report = run_mission(load_mission(MISSION), RunOptions(
        lockstep=True, seed=3, output=tmp_path, link_faults=fade), None)
    d = report.to_dict()
    assert not report.ok and "vehicle 3" in d["reason"] and "link lost" in d["reason"], d
    assert d["collision_source"] == "truth" and d["collisions"] == 0 and d["touched"] == []
    assert len(d["recordings"]) == 5
    for path in d["recordings"]:
        rec = open_recording(path)
        sysid = int(path.rsplit("vehicle", 1)[1].split(".")[0])
        states = [(m["t_s"], m["state"]) for _, _, m in rec.messages(["/gcs/supervisor"])]
        # disarmed before the mission ended, or disarmed while the station quit (it releases
        # only once a heartbeat shows it disarmed): the heartbeat below says which is true
        assert states[-1][1] in ("disarmed", "released"), (sysid, states[-5:])
        last = [m for _, _, m in rec.messages(["/vehicle/heartbeat"])][-1]
        assert not last["armed"]
        truth = [m for _, _, m in rec.messages(["/vehicle/sim_truth"])]
        assert -truth[-1]["pos_n"]["z"] < 0.1  # on the floor (SITL frame: z from the start)
        after = [m for m in truth if m["t_s"] > FADE_AT_S]
        # every touchdown soft: nothing came down faster than a landing does
        assert max(m["vel_n"]["z"] for m in after) < 1.0, sysid
        if sysid == 3:
            # link lost, then silence; when it is back the vehicle is the firmware's (LAND)
            # and the station never takes it back up
            names = [s for _, s in states]
            lost = names.index("link_lost")
            assert not {"takeoff", "hold", "spool_up"} & set(names[lost:]), states
        else:
            # the others were landed by the mission once vehicle 3 was gone
            landing = next(t for t, s in states if s == "vehicle")
            assert landing > FADE_AT_S
