"""`logs check` on the recordings of a mission (lockstep; the other kinds in
tests/e2e/test_mission_one_loop.py): the checks measure what a
mission records, a clean mission fails none, and one recording per vehicle is checked."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from gcs.flight_check import gather_file
from lab.cli import main
from logs.check import Status, evaluate, load_thresholds, measure

MISSIONS = Path(__file__).resolve().parents[2] / "missions"
ALWAYS = ("link.loss_pct", "link.longest_silence_s", "loop.overruns_pct",
          "estimator.innovation_rms_m",
          "vibration.acc_rms_z_mps2", "control.stick_limit_pct", "power.min_cell_v",
          "events.failsafes")


# the flock and radiation missions' lockstep recordings are checked where they are flown already
# (tests/e2e/test_mission_one_loop.py): five vehicles, or a mapping flight, are minutes of a core
@pytest.mark.parametrize("mission", ["epbha_table"])
def test_every_mission_kinds_recordings_are_checked(mission: str, tmp_path: Path,
                                                   capsys: pytest.CaptureFixture[str]) -> None:
    code = main(["mission", "run", str(MISSIONS / f"{mission}.toml"), "--lockstep", "--seed",
                 "1", "-o", str(tmp_path), "--json"])
    summary = json.loads(capsys.readouterr().out)
    assert code == 0, summary
    assert "live checks PASS" in json.dumps(summary)  # the station's own summary line
    recordings = sorted(tmp_path.glob("*.mcap"))
    assert recordings
    for path in recordings:
        results = {r.key: r for r in evaluate(measure(gather_file(path)),
                                              load_thresholds(None))}
        assert not [k for k, r in results.items() if r.status is Status.FAIL], path
        assert all(results[k].status is not Status.SKIP for k in ALWAYS), path
    capsys.readouterr()
    assert main(["logs", "check", str(recordings[0])]) == 0  # and the command says so
