"""Forwarding with a real second ground station: MAVProxy on `fly --forward` against copter4.

MAVProxy (from PyPI) connects to the forward port as it would to a vehicle: it must see the
vehicle, download its parameters, change one that the vehicle then reports, and have its
`rc 3 1800` refused while quadgcs holds the altitude undisturbed.
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
import threading
import time
from collections.abc import Callable
from pathlib import Path

import pytest

from logs import open_recording

ROOT = Path(__file__).resolve().parents[2]
MAVPROXY = Path(sys.executable).parent / "mavproxy.py"
FORWARD_LINE = re.compile(r"^forward: tcpin:127\.0\.0\.1:(\d+)")


class Lines:
    """A process's output lines, read on a thread so the test can wait on them."""

    def __init__(self, stream) -> None:
        self.lines: list[str] = []
        self._thread = threading.Thread(target=self._read, args=(stream,), daemon=True)
        self._thread.start()

    def _read(self, stream) -> None:
        for line in stream:
            self.lines.append(line.rstrip("\n"))

    def text(self) -> str:
        return "\n".join(self.lines)


def wait_for(what: str, done: Callable[[], object], timeout_s: float,
             each: Callable[[], None] | None = None, every_s: float = 1.0) -> object:
    """Wait until `done()` is truthy (doing `each()` every `every_s`); fail naming `what`."""
    deadline = time.monotonic() + timeout_s
    next_each = 0.0
    pause = threading.Event()
    while time.monotonic() < deadline:
        value = done()
        if value:
            return value
        if each is not None and time.monotonic() >= next_each:
            each()
            next_each = time.monotonic() + every_s
        pause.wait(0.05)
    raise AssertionError(f"{what}: not within {timeout_s:.0f} s")


@pytest.mark.e2e
@pytest.mark.timeout(240)
def test_mavproxy_shares_the_vehicle_but_not_the_sticks(tmp_path: Path) -> None:
    out = tmp_path / "flight.mcap"
    fly = subprocess.Popen(
        [sys.executable, "-m", "gcs", "fly", "--profile", "copter4", "--fix-failsafe",
         "--forward", "tcpin:127.0.0.1:0", "--hold", "30", "--seed", "3", "--json",
         "-o", str(out)],
        cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    fly_err = Lines(fly.stderr)
    mavproxy: subprocess.Popen[str] | None = None
    try:
        port = wait_for("fly's forward port", lambda: next(
            (m.group(1) for m in map(FORWARD_LINE.match, fly_err.lines) if m), None), 60.0)
        mavproxy = subprocess.Popen(
            [str(MAVPROXY), f"--master=tcp:127.0.0.1:{port}", "--source-system=254"],
            cwd=tmp_path, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT, text=True)
        mp = Lines(mavproxy.stdout)
        assert mavproxy.stdin is not None
        stdin = mavproxy.stdin

        def command(line: str) -> None:
            stdin.write(line + "\n")
            stdin.flush()

        wait_for("MAVProxy sees the vehicle", lambda: "Detected vehicle 1:1" in mp.text(), 60.0)
        wait_for("MAVProxy reads the parameters",
                 lambda: re.search(r"Received \d+ parameters", mp.text()), 90.0)
        command("param set RTL_ALT 1700")
        wait_for("the vehicle reports the new RTL_ALT to MAVProxy",
                 lambda: re.search(r"RTL_ALT\s+1700", mp.text()), 20.0,
                 each=lambda: command("param show RTL_ALT"))
        assert fly.poll() is None, "the flight ended before MAVProxy's sticks were tried"
        command("rc 3 1800")
        stdout, _ = fly.communicate(timeout=120)
        assert fly.returncode == 0, fly_err.text()
    finally:
        if mavproxy is not None:
            mavproxy.kill()
            mavproxy.wait(10)
        if fly.poll() is None:
            fly.kill()
            fly.wait(10)
    summary = json.loads(stdout.strip().splitlines()[-1])
    fwd = summary["forward"]
    assert fwd["refused_overrides"] >= 1, fwd
    assert fwd["to_vehicle"] >= 1 and fwd["to_stations"] > 1000, fwd
    # MAVProxy's 1800 µs never reached the vehicle: the hold is as undisturbed as ever
    assert summary["error_source"] == "truth"
    assert summary["rms_error_m"] < 0.03 and summary["max_error_m"] < 0.1, summary
    rec = open_recording(out)
    refusals = [m for _t, _ns, m in rec.messages(["/link/events"])
                if m.get("kind") == "forward" and "RC override refused" in m.get("detail", "")]
    assert refusals, "no refusal reported in the recording"
    values = [m for _t, _ns, m in rec.messages(["/vehicle/param_value"])
              if m.get("name") == "RTL_ALT"]
    assert values and abs(values[-1]["value"] - 1700.0) < 1e-3  # quadgcs heard it too
