"""`quadgcs fly` as a user runs it: a whole flight with a recording, and bad input."""

from __future__ import annotations

import json
import queue
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from logs import open_recording
from tests.e2e.sitl_proc import SitlProcess

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
    # 3.2.1 gives no version at connect (only its parameter list carries the banner)
    assert (summary["firmware"], summary["firmware_source"]) == (
        "ArduCopter 3.x", "parameters: THR_MID"), summary
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
        # a deadline shorter than one retry: the refusal is the whole answer
        (["fly", "--connect", "tcp:127.0.0.1:1", "--connect-timeout", "0.3", "--no-record"], 1,
         "tcp:127.0.0.1:1: no vehicle within 0.3 s (connection refused"),
        (["fly", "--connect", "tcp:127.0.0.1:1", "--connect-timeout", "0", "--no-record"], 2,
         "--connect-timeout 0"),
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


def _free_tcp_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


def _lines(stream: object) -> queue.Queue[str]:
    """A stream's lines as they come, read on a thread (a pipe's readline blocks)."""
    out: queue.Queue[str] = queue.Queue()

    def pump() -> None:
        for line in stream:  # type: ignore[attr-defined]
            out.put(line.rstrip("\n"))

    threading.Thread(target=pump, daemon=True).start()
    return out


def _wait_for_line(lines: queue.Queue[str], needle: str, timeout_s: float) -> list[str]:
    seen: list[str] = []
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        try:
            line = lines.get(timeout=max(0.0, deadline - time.monotonic()))
        except queue.Empty:
            break
        seen.append(line)
        if needle in line:
            return seen
    raise AssertionError(f"no line with {needle!r} within {timeout_s} s: {seen}")


@pytest.mark.e2e
@pytest.mark.timeout(240)
def test_fly_connect_waits_for_a_vehicle_that_is_not_up_yet() -> None:
    port = _free_tcp_port()
    url = f"tcp:127.0.0.1:{port}"
    fly = subprocess.Popen([sys.executable, "-m", "gcs", "fly", "--connect", url,
                            "--connect-timeout", "90", "--json", "--hold", "2", "--no-record",
                            "--fix-failsafe"],  # 4.x ships its GCS failsafe off
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=ROOT)
    sitl: SitlProcess | None = None
    try:
        err = _lines(fly.stderr)
        # the station is up and waiting before the vehicle exists
        first = _wait_for_line(err, f"waiting for the vehicle on {url}", 60.0)
        assert "connection refused" in first[-1] and "giving up in 90 s" in first[-1]
        assert fly.poll() is None
        sitl = SitlProcess(["--tcp", str(port), "--profile", "copter4"], ROOT)
        out, _ = fly.communicate(timeout=180)
        rest: list[str] = []
        while not err.empty():
            rest.append(err.get())
        assert fly.returncode == 0, (out, first, rest)
        summary = json.loads(out.strip().splitlines()[-1])
        assert summary["rms_error_m"] < 0.15, summary
        # the firmware named, and how: 4.x answers AUTOPILOT_VERSION
        assert (summary["firmware"], summary["firmware_source"]) == (
            "ArduCopter V4.7.0-dev", "AUTOPILOT_VERSION"), summary
    finally:
        if fly.poll() is None:
            fly.kill()
            fly.wait()
        if sitl is not None:
            sitl.stop()


@pytest.mark.e2e
def test_fly_connect_gives_up_at_its_deadline_with_one_line() -> None:
    port = _free_tcp_port()  # nothing listens there
    url = f"tcp:127.0.0.1:{port}"
    t0 = time.monotonic()
    proc = quadgcs("fly", "--connect", url, "--connect-timeout", "2", "--no-record",
                   timeout_s=60.0)
    waited_s = time.monotonic() - t0
    assert proc.returncode == 1, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert lines[0].startswith(f"waiting for the vehicle on {url} (connection refused")
    assert lines[-1].startswith(f"quadgcs fly: {url}: no vehicle within 2 s (connection "
                                "refused"), lines
    assert "--connect-timeout" in lines[-1] and "Traceback" not in proc.stderr
    assert waited_s >= 1.5  # it did retry until its deadline, not give up at the refusal
