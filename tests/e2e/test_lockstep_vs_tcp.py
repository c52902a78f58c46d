"""A lockstep flight is the flight a pilot gets over TCP: the same seed and plan hold the altitude
as well (RMS within 20 %), at 1× over real sockets and at CPU speed in one process."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PLAN = ("--seed", "2", "--hold", "15", "--no-record", "--json")


def _fly(*argv: str) -> dict:
    proc = subprocess.run([sys.executable, "-m", "gcs", "fly", *argv, *PLAN], capture_output=True,
                          text=True, timeout=150, cwd=ROOT)
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout.strip().splitlines()[-1])


@pytest.mark.e2e
@pytest.mark.timeout(200)
def test_lockstep_hold_agrees_with_tcp_at_1x() -> None:
    tcp = _fly()
    lockstep = _fly("--lockstep")
    for d in (tcp, lockstep):
        assert d["status"] == "ok" and d["error_source"] == "truth"
        assert d["truth_coverage"] > 0.95
    ratio = lockstep["rms_error_m"] / tcp["rms_error_m"]
    assert 0.8 <= ratio <= 1.2, (tcp["rms_error_m"], lockstep["rms_error_m"])
    # the hover throttle the station learned is the vehicle's, however it was reached
    assert lockstep["hover_throttle"] == pytest.approx(tcp["hover_throttle"], abs=0.02)
    # only the TCP flight knows a wall clock: its loop jitters, the lockstep one cannot
    assert tcp["jitter_p99_ms"] > 0.0 and lockstep["jitter_p99_ms"] == 0.0
