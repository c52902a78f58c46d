"""The fault proxy over real sockets and a real pseudo-terminal pair, with seeded faults.

A fake vehicle (a TCP server or a pty the test writes MAVLink frames into) sits behind the
proxy and a fake station reads what comes through with pymavlink's own parser. Every wait is
on a condition with a deadline: the proxy's counters, bytes received, or the proxy's clock.
"""

from __future__ import annotations

import os
import re
import select
import signal
import socket
import subprocess
import sys
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest
import serial
from pymavlink.dialects.v20 import ardupilotmega as mavlink

from sitl.fault_frames import Direction, FrameSplitter, flip_one_bit
from sitl.fault_proxy import FaultProxy

ROOT = Path(__file__).resolve().parents[2]
DEADLINE_S = 10.0


def frames(n: int, *, v1: bool = False, sysid: int = 1, signed: bool = False) -> list[bytes]:
    """`n` distinct ATTITUDE frames (time_boot_ms = index)."""
    mav = mavlink.MAVLink(None, srcSystem=sysid, srcComponent=1)
    if signed:
        mav.signing.secret_key = bytes(range(32))
        mav.signing.link_id = 1
        mav.signing.sign_outgoing = True
    return [mavlink.MAVLink_attitude_message(i, 0.1, 0.2, 0.3, 0.0, 0.0, 0.0)
            .pack(mav, force_mavlink1=v1) for i in range(n)]


def parse(data: bytes) -> list[Any]:
    """Everything pymavlink makes of `data`, BAD_DATA included."""
    mav = mavlink.MAVLink(None)
    mav.robust_parsing = True
    return mav.parse_buffer(data) or []


def read_until(fd_read: Callable[[], bytes], fileno: int, done: Callable[[bytes], bool],
               timeout_s: float = DEADLINE_S) -> bytes:
    """Read from a descriptor until `done(all bytes so far)` or the deadline."""
    got = bytearray()
    deadline = time.monotonic() + timeout_s
    while not done(bytes(got)) and time.monotonic() < deadline:
        r, _, _ = select.select([fileno], [], [], 0.05)
        if r:
            chunk = fd_read()
            if not chunk:
                break
            got += chunk
    return bytes(got)


class TcpRig:
    """Fake vehicle server ← proxy ← fake station client, all on 127.0.0.1."""

    def __init__(self, seed: int = 1, time_scale: float = 1.0) -> None:
        self.server = socket.create_server(("127.0.0.1", 0))
        self.proxy = FaultProxy(target=self.server.getsockname(), seed=seed,
                                time_scale=time_scale).start()
        self.station = socket.create_connection(("127.0.0.1", self.proxy.port), 5.0)
        self.server.settimeout(5.0)
        self.vehicle, _ = self.server.accept()

    def read(self, sock: socket.socket, n_bytes: int, timeout_s: float = DEADLINE_S) -> bytes:
        return read_until(lambda: sock.recv(65536), sock.fileno(),
                          lambda b: len(b) >= n_bytes, timeout_s)

    def close(self) -> None:
        self.proxy.stop()
        for s in (self.station, self.vehicle, self.server):
            s.close()


@pytest.fixture
def rig() -> Iterator[TcpRig]:
    r = TcpRig()
    yield r
    r.close()


def test_splitter_cuts_v1_v2_and_signed_frames_and_resyncs_after_a_stray_magic() -> None:
    v1, v2, signed = frames(1, v1=True)[0], frames(1)[0], frames(1, signed=True)[0]
    assert len(signed) == len(v2) + 13
    stream = b"\x01\x02" + v1 + b"\xfd\x09junk" + v2 + signed
    sp = FrameSplitter()
    # byte by byte: partial headers and payloads wait for the rest
    chunks = [c for i in range(len(stream)) for c in sp.feed(stream[i:i + 1])]
    got = [(f, c) for f, c in chunks]
    assert [c for f, c in got if f] == [v1, v2, signed]
    assert b"".join(c for _, c in got) == stream
    assert b"".join(c for f, c in got if not f) == b"\x01\x02\xfd\x09junk"


@pytest.mark.parametrize("v1", [True, False])
def test_a_flipped_bit_fails_pymavlinks_crc_and_keeps_the_framing(v1: bool) -> None:
    f = frames(1, v1=v1)[0]
    for k in range(40):
        bad = flip_one_bit(f, k / 40)
        assert sum(bin(a ^ b).count("1") for a, b in zip(bad, f, strict=True)) == 1
        (msg,) = parse(bad)
        assert msg.get_type() == "BAD_DATA" and "invalid MAVLink CRC" in msg.reason


def test_relays_both_ways_byte_for_byte(rig: TcpRig) -> None:
    down = b"".join(frames(200)) + b"not mavlink"
    up = b"".join(frames(100, v1=True, sysid=255))
    rig.vehicle.sendall(down)
    rig.station.sendall(up)
    assert rig.read(rig.station, len(down)) == down
    assert rig.read(rig.vehicle, len(up)) == up
    assert rig.proxy.wait_until(lambda p: p.counters("down").other_bytes == 11, DEADLINE_S)
    d, u = rig.proxy.counters(Direction.DOWN), rig.proxy.counters(Direction.UP)
    assert (d.frames_passed, d.frames_dropped, d.frames_corrupted) == (200, 0, 0)
    assert (u.frames_passed, u.bytes_in, u.bytes_out) == (100, len(up), len(up))
    assert rig.proxy.counters("both").frames_in == 300


def test_a_window_drops_exactly_that_direction_and_then_ends() -> None:
    rig = TcpRig(time_scale=10.0)  # a 3 s simulated window lasts 0.3 s of wall time
    try:
        window = rig.proxy.drop("down", 3.0)
        rig.vehicle.sendall(b"".join(frames(50)))
        up = b"".join(frames(50, sysid=255))
        rig.station.sendall(up)
        assert rig.read(rig.vehicle, len(up)) == up  # the uplink is untouched
        assert rig.proxy.wait_until(lambda p: p.counters("down").frames_in == 50, DEADLINE_S)
        assert rig.proxy.counters("down").frames_dropped == 50
        assert rig.proxy.counters("up").frames_dropped == 0
        assert rig.proxy.wait_until(lambda p: p.now_s() >= window.end_s, DEADLINE_S)
        after = b"".join(frames(20))
        rig.vehicle.sendall(after)
        # nothing from inside the window arrives late: the first bytes are the new frames
        assert rig.read(rig.station, len(after)) == after
        assert rig.proxy.counters("down").frames_passed == 20
    finally:
        rig.close()


def test_loss_rate_is_within_tolerance_and_repeats_with_the_seed() -> None:
    counts = []
    n = 4000
    for _ in range(2):
        rig = TcpRig(seed=7)
        fates: list[tuple[Direction, str]] = []
        rig.proxy.tap = lambda d, fate, _frame, _t, seen=fates: seen.append((d, fate))
        try:
            rig.proxy.set("down", loss=0.3)
            rig.vehicle.sendall(b"".join(frames(n)))
            assert rig.proxy.wait_until(lambda p: p.counters("down").frames_in == n, DEADLINE_S)
            c = rig.proxy.counters("down")
            got = [m for m in parse(rig.read(rig.station, c.bytes_out))
                   if m.get_type() == "ATTITUDE"]
            assert len(got) == c.frames_passed
            # binomial sigma is 0.7 % at 4000 frames: 3 % is over 4 sigma
            assert abs(c.frames_dropped / n - 0.3) < 0.03
            assert fates.count((Direction.DOWN, "dropped")) == c.frames_dropped  # the tap saw all
            counts.append(c.frames_dropped)
        finally:
            rig.close()
    assert counts[0] == counts[1]


def test_flipped_frames_fail_the_crc_at_the_station(rig: TcpRig) -> None:
    rig.proxy.set("both", bitflip=0.2)
    n = 1000
    rig.vehicle.sendall(b"".join(frames(n)))
    assert rig.proxy.wait_until(lambda p: p.counters("down").frames_in == n, DEADLINE_S)
    c = rig.proxy.counters("down")
    msgs = parse(rig.read(rig.station, c.bytes_out))
    bad = [m for m in msgs if m.get_type() == "BAD_DATA"]
    assert 150 < c.frames_corrupted < 250
    assert len(bad) == c.frames_corrupted
    assert all("invalid MAVLink CRC" in m.reason for m in bad)
    assert sum(m.get_type() == "ATTITUDE" for m in msgs) == c.frames_passed == n - len(bad)


def test_delay_holds_frames_back_in_simulated_seconds() -> None:
    rig = TcpRig(time_scale=2.0)
    try:
        rig.proxy.set("up", delay_s=1.0)  # 1 simulated second = 0.5 s of wall time
        f = frames(1, sysid=255)[0]
        t0 = time.monotonic()
        rig.station.sendall(f)
        assert rig.read(rig.vehicle, len(f)) == f
        assert 0.45 <= time.monotonic() - t0 < 5.0
    finally:
        rig.close()


def test_stop_closes_every_socket_and_the_thread() -> None:
    fds_before = len(os.listdir("/proc/self/fd"))
    rig = TcpRig()
    port = rig.proxy.port
    rig.proxy.stop()
    assert not rig.proxy.running
    # the station sees the connection end, and nobody listens any more
    assert read_until(lambda: rig.station.recv(100), rig.station.fileno(), lambda b: False,
                      2.0) == b""
    with pytest.raises(OSError):
        socket.create_connection(("127.0.0.1", port), 1.0).close()
    rig.proxy.stop()  # idempotent
    rig.close()
    assert len(os.listdir("/proc/self/fd")) == fds_before


def test_serial_bridge_keeps_the_line_pace_and_drops_one_way() -> None:
    master, slave = os.openpty()  # the "vehicle's" pty: the test writes into its master
    os.set_blocking(master, False)
    import termios
    import tty
    tty.setraw(slave, termios.TCSANOW)
    proxy = FaultProxy(serial_port=os.ttyname(slave), seed=3, time_scale=4.0).start()
    assert proxy.serial_path is not None and proxy.address == proxy.serial_path
    station = serial.Serial(proxy.serial_path, 115200, timeout=0)
    try:
        down = b"".join(frames(200))  # ~7 kB: at 4 x 11.5 kB/s about 0.15 s of line time
        t0 = time.monotonic()
        os.write(master, down)
        got = read_until(station.read_all, station.fileno(), lambda b: len(b) >= len(down))
        elapsed = time.monotonic() - t0
        assert got == down
        rate = 115200 / 10 * 4.0
        assert elapsed >= (len(down) - rate * 0.05) / rate * 0.9  # no faster than the line
        proxy.drop("up", 100.0)
        station.write(b"".join(frames(30, sysid=255)))
        assert proxy.wait_until(lambda p: p.counters("up").frames_dropped == 30, DEADLINE_S)
        one = frames(1)[0]
        os.write(master, one)
        # the line paces bytes out in chunks: wait for the whole frame, not the first chunk
        assert read_until(station.read_all, station.fileno(), lambda b: len(b) >= len(one)) \
            == one
        r, _, _ = select.select([master], [], [], 0.0)
        assert not r  # nothing reached the vehicle while the uplink was down
    finally:
        station.close()
        proxy.stop()
        os.close(master)
        os.close(slave)


def test_cli_drops_the_downlink_window_and_reports_counters() -> None:
    server = socket.create_server(("127.0.0.1", 0))
    port = server.getsockname()[1]
    # a 20 s simulated window at 10x: 2 s of wall time from the station's connection
    proc = subprocess.Popen(
        [sys.executable, "-m", "sitl.fault_proxy_cli", "--target", f"tcp:127.0.0.1:{port}",
         "--drop", "down:0+20", "--time-scale", "10", "--seed", "2"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=ROOT)
    try:
        assert proc.stdout is not None
        line = proc.stdout.readline().strip()
        assert line.startswith("proxy tcp:127.0.0.1:") and proc.stdout.readline() == "ready\n"
        station = socket.create_connection(("127.0.0.1", int(line.rsplit(":", 1)[1])), 5.0)
        server.settimeout(5.0)
        vehicle, _ = server.accept()
        vehicle.sendall(b"".join(frames(10)))  # inside the window
        up = b"".join(frames(10, sysid=255))
        station.sendall(up)
        assert read_until(lambda: vehicle.recv(65536), vehicle.fileno(),
                          lambda b: len(b) >= len(up)) == up
        # the vehicle keeps talking until the window is over and a frame comes through
        one = frames(11)[10]
        got, deadline = b"", time.monotonic() + DEADLINE_S
        while not got and time.monotonic() < deadline:
            vehicle.sendall(one)
            got = read_until(lambda: station.recv(65536), station.fileno(), len, 0.05)
        assert got[:len(one)] == one
        proc.send_signal(signal.SIGTERM)
        _, err = proc.communicate(timeout=10)
        assert proc.returncode == 0, err
        assert "station arrived; down drop from t=0 s for 20 s" in err
        assert "up: 10 frames in: 10 passed, 0 dropped" in err
        m = re.search(r"down: (\d+) frames in: (\d+) passed, (\d+) dropped", err)
        assert m is not None and int(m[3]) >= 10 and int(m[2]) >= 1, err
        station.close()
        vehicle.close()
    finally:
        if proc.poll() is None:
            proc.kill()
        server.close()


@pytest.mark.parametrize("flag", ["--drop down:30", "--loss sideways:0.3", "--delay up:-1",
                                  "--bitflip both:0.1@5+0"])
def test_cli_bad_flag_is_one_line(flag: str) -> None:
    done = subprocess.run([sys.executable, "-m", "sitl.fault_proxy_cli", "--target",
                           "tcp:127.0.0.1:5760", *flag.split()], capture_output=True,
                          text=True, cwd=ROOT, timeout=30)
    assert done.returncode == 2
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("fault_proxy: ") and flag.split()[0] in lines[0]
