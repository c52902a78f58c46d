"""`quadgcs fly` as a user runs it: a whole flight with a recording, and bad input."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from logs import open_recording

ROOT = Path(__file__).resolve().parents[2]


def quadgcs(*argv: str, timeout_s: float = 180.0) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "gcs", *argv], capture_output=True, text=True,
                          timeout=timeout_s, cwd=ROOT)


@pytest.mark.e2e
@pytest.mark.timeout(240)
def test_fly_json_records_the_flight(tmp_path: Path) -> None:
    out = tmp_path / "flight.mcap"
    proc = quadgcs("fly", "--json", "--hold", "4", "--speedup", "2", "--seed", "2",
                   "-o", str(out))
    assert proc.returncode == 0, proc.stderr
    summary = json.loads(proc.stdout.strip().splitlines()[-1])
    for key in ("rms_error_m", "max_error_m", "jitter_p99_ms", "overruns", "recording"):
        assert key in summary
    assert summary["error_source"] == "truth"
    assert summary["rms_error_m"] < 0.1
    assert summary["recording"] == str(out)
    rec = open_recording(out)
    counts = rec.counts
    for topic in ("/gcs/estimate", "/gcs/alt_controller", "/gcs/rc_override", "/gcs/loop",
                  "/vehicle/attitude", "/vehicle/imu", "/vehicle/rangefinder"):
        assert counts.get(topic, 0) > 50, topic
    # one override per tick: the loop never stalls the stream
    assert abs(counts["/gcs/rc_override"] - counts["/gcs/loop"]) <= 2


@pytest.mark.parametrize(
    ("argv", "code", "needle"),
    [
        (["fly", "--alt", "9"], 2, "0.2..3.5"),
        (["fly", "--world", "no/such/world.toml"], 2, "no such file"),
        (["fly", "--speedup", "0"], 2, "--speedup"),
        # a sped-up clock only for a simulator on this machine (refused before any connection)
        (["fly", "--speedup", "2", "--connect", "tcp:192.0.2.1:5760"], 2, "real time"),
        (["fly", "--speedup", "2", "--connect", "/dev/ttyUSB0"], 2, "real time"),
        (["fly", "--connect", "tcp:127.0.0.1:1", "--no-record"], 1, "127.0.0.1:1"),
        (["fly", "--connect", "bogus::url", "--no-record"], 2, "bogus"),
    ],
)
def test_bad_input_ends_in_one_line(argv: list[str], code: int, needle: str) -> None:
    proc = quadgcs(*argv, timeout_s=60.0)
    assert proc.returncode == code, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("quadgcs fly:"), proc.stderr
    assert needle in lines[0]
    assert "Traceback" not in proc.stderr
