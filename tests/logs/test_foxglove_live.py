"""The live view: a real `quadgcs fly --foxglove` on the bundled SITL, a real WebSocket client.

The client speaks Foxglove's protocol as foxglove-sdk 0.30 serves it (subprotocol
`foxglove.sdk.v1`), subscribes to the pose and altitude topics and decodes every message while
the vehicle flies; the well-known messages validate against Foxglove's official schemas.
"""

from __future__ import annotations

import asyncio
import re
import socket
import subprocess
import sys
import threading
from pathlib import Path

import pytest

from gcs.foxglove_feed import POSE_ESTIMATE, POSE_MOCAP
from logs import RecordingError, open_recording
from logs.foxglove import foxglove_transform
from logs.live import LiveView, parse_address
from tests.logs.foxglove_client import SUBPROTOCOL, FoxgloveClient, Received
from tests.logs.official_schemas import problems, require_schemas

ROOT = Path(__file__).resolve().parents[2]
ESTIMATE = "/gcs/estimate"
URL_LINE = re.compile(r"foxglove: live view on (ws://\S+)")


class StderrLines:
    """A child's stderr, read on a thread so a test can wait for a line with a deadline."""

    def __init__(self, proc: subprocess.Popen[str]) -> None:
        self.lines: list[str] = []
        self._cond = threading.Condition()
        self._proc = proc
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self) -> None:
        assert self._proc.stderr is not None
        for line in self._proc.stderr:
            with self._cond:
                self.lines.append(line)
                self._cond.notify_all()
        with self._cond:
            self.lines.append("")  # end of stream
            self._cond.notify_all()

    def wait_for(self, pattern: re.Pattern[str], timeout_s: float) -> re.Match[str] | None:
        """The first line matching `pattern`, or None at the deadline or at the end."""
        def found() -> re.Match[str] | bool | None:
            for line in self.lines:
                m = pattern.search(line)
                if m:
                    return m
            return bool(self.lines) and self.lines[-1] == ""

        with self._cond:
            result = self._cond.wait_for(found, timeout_s)
        return result if isinstance(result, re.Match) else None


def _flew(r: Received) -> bool:
    poses = r.by_topic.get(POSE_ESTIMATE, [])
    return len(r.by_topic.get(ESTIMATE, [])) >= 40 and any(
        m["translation"]["z"] < -0.7 for _, m in poses)


@pytest.mark.e2e
def test_live_fly_streams_pose_and_altitude_in_order(tmp_path: Path) -> None:
    require_schemas()
    proc = subprocess.Popen(
        [sys.executable, "-m", "gcs", "fly", "--hold", "3", "--speedup", "2", "--seed", "5",
         "--foxglove", "127.0.0.1:0", "-o", str(tmp_path)],
        cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    err = StderrLines(proc)
    try:
        m = err.wait_for(URL_LINE, 120.0)
        assert m, "".join(err.lines)[-2000:]

        async def watch() -> tuple[Received, str | None]:
            async with FoxgloveClient(m.group(1), {POSE_ESTIMATE, POSE_MOCAP, ESTIMATE}) as c:
                await c.run_until(_flew, 120.0)
                return c.received, c.subprotocol

        received, subprotocol = asyncio.run(watch())
    finally:
        proc.wait(timeout=180)  # it lands and exits by itself after the hold
    assert proc.returncode in (0, 3), "".join(err.lines)[-2000:]
    assert subprotocol == SUBPROTOCOL
    assert _flew(received), {t: len(v) for t, v in received.by_topic.items()}
    assert received.schema_names[POSE_ESTIMATE] == "foxglove.FrameTransform"
    assert received.encodings[POSE_ESTIMATE] == "json"
    for topic, series in received.by_topic.items():
        times = [t for t, _ in series]
        assert times == sorted(times), topic  # in order, as published
    alts = [msg["alt_m"] for _, msg in received.by_topic[ESTIMATE]]
    assert max(alts) > 0.7
    t_s = [msg["t_s"] for _, msg in received.by_topic[ESTIMATE]]
    assert t_s == sorted(t_s) and len(set(t_s)) == len(t_s)
    for topic in (POSE_ESTIMATE, POSE_MOCAP):
        for log_ns, msg in received.by_topic.get(topic, []):
            assert problems("foxglove.FrameTransform", msg) == [], topic
            stamp = msg["timestamp"]
            assert stamp["sec"] * 10**9 + stamp["nsec"] == log_ns


def test_live_view_in_process_sends_what_was_put() -> None:
    with LiveView("127.0.0.1", 0, anchor_ns=10**18) as live:
        stop = threading.Event()

        def produce() -> None:
            # a channel is advertised with its first message and a client subscribes after
            # that: keep publishing (every 20 ms, as a flight would) until the test has both
            while not stop.wait(0.02):
                live.put("/tf/x", 1.0, foxglove_transform("ned", "x", (1, 2, 3)))
                live.put("/plain", 1.0, {"a_m": 1.5, "n": 2})

        async def watch() -> Received:
            async with FoxgloveClient(live.url, {"/tf/x", "/plain"}) as c:
                assert await c.run_until(lambda r: {"/tf/x", "/plain"} <= r.by_topic.keys(),
                                         20.0)
                return c.received

        producer = threading.Thread(target=produce, daemon=True)
        producer.start()
        try:
            received = asyncio.run(watch())
        finally:
            stop.set()
            producer.join()
    log_ns, tf = received.by_topic["/tf/x"][0]
    assert log_ns == 10**18 + 10**9
    assert tf["translation"] == {"x": 1.0, "y": 2.0, "z": 3.0}
    assert received.by_topic["/plain"][0][1] == {"a_m": 1.5, "n": 2}


def test_addresses_and_a_busy_port() -> None:
    assert parse_address("8765") == ("127.0.0.1", 8765)
    assert parse_address("0.0.0.0:9000") == ("0.0.0.0", 9000)
    for bad in ("", "host:", "http", "1:99999", ":80"):
        with pytest.raises(RecordingError, match="expected"):
            parse_address(bad)
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        s.listen()
        with pytest.raises(RecordingError, match="cannot serve"):
            LiveView("127.0.0.1", s.getsockname()[1])


@pytest.mark.e2e
def test_live_replay_serves_the_recording(recorded_flight: tuple[Path, dict[str, int]]) -> None:
    path, counts = recorded_flight
    recording = open_recording(path)
    topics = {t for t, n in counts.items() if n > 0 and t.startswith("/gcs")}
    assert topics
    expected = {t: [(log_ns, msg) for _, log_ns, msg in recording.messages([t])] for t in topics}
    proc = subprocess.Popen(
        [sys.executable, "-m", "gcs", "replay", str(path), "--headless", "--speed", "2",
         "--foxglove", "127.0.0.1:0"],
        cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    err = StderrLines(proc)
    try:
        m = err.wait_for(URL_LINE, 60.0)
        assert m, "".join(err.lines)[-2000:]

        async def watch() -> Received:
            async with FoxgloveClient(m.group(1), topics) as c:
                # until the replay ends and the server closes the connection
                await c.run_until(lambda r: False, 60.0)
                return c.received

        received = asyncio.run(watch())
    finally:
        proc.wait(timeout=60)
    assert proc.returncode == 0, "".join(err.lines)[-2000:]
    assert received.by_topic.keys() == topics
    for topic, series in received.by_topic.items():
        # subscribed a moment after the replay started: a tail of the recording, exactly
        assert len(series) > len(expected[topic]) // 2, topic
        assert series == expected[topic][-len(series):], topic
