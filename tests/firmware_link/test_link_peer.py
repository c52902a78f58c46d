"""VehicleLink against a small MAVLink vehicle on a real TCP socket and a real pseudo-terminal."""

from __future__ import annotations

import socket
import threading
import time
from collections.abc import Callable, Iterator

import pytest

from firmware_link import LinkError, LinkUsageError, VehicleLink
from firmware_link.protocol import mavlink
from firmware_link.records import (
    CommandAck,
    Dialect,
    FlightMode,
    Imu,
    LinkEvent,
    LinkEventKind,
    Proximity,
    Radiation,
    Rangefinder,
    RcCommand,
)
from tests.firmware_link.peer import FakeVehicle, wait_until
from worldfile import key_from_passphrase

KEY = key_from_passphrase("quadgcs test key")


def poll_until(link: VehicleLink, done: Callable[[list], bool], timeout_s: float = 5.0) -> list:
    """Poll the link until `done(all records so far)` holds; fail after the deadline."""
    seen: list = []
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        seen.extend(link.poll())
        if done(seen):
            return seen
        link._wait_readable(time.monotonic() + 0.005)
    raise AssertionError(f"condition not met in {timeout_s} s; last records {seen[-5:]}")


def events(records: list, kind: LinkEventKind) -> list[LinkEvent]:
    return [r for r in records if isinstance(r, LinkEvent) and r.kind is kind]


@pytest.fixture(params=[("copter4", False), ("apm25", False), ("copter4", True), ("apm25", True)],
                ids=["copter4-tcp", "apm25-tcp", "copter4-pty", "apm25-pty"])
def vehicle(request) -> Iterator[FakeVehicle]:
    profile, serial = request.param
    v = FakeVehicle(profile, serial=serial).start()
    yield v
    v.stop()


def test_connect_detects_dialect_and_flies_the_basics(vehicle: FakeVehicle) -> None:
    tapped: list[tuple[str, float, bytes]] = []
    with VehicleLink.open(vehicle.url, on_raw=lambda *a: tapped.append(a)) as link:
        want = Dialect.APM25 if vehicle.profile == "apm25" else Dialect.COPTER4
        assert link.dialect is want
        assert link.target_system == 1
        assert link.signing is False
        serial = not vehicle.url.startswith("tcp:")
        assert link.capacity_bytes_per_s == (11520.0 if serial else None)
        first = link.poll()
        assert events(first, LinkEventKind.CONNECTED) and events(first, LinkEventKind.DIALECT)
        (signing,) = events(first, LinkEventKind.SIGNING)
        if want is Dialect.APM25:
            assert "speaks MAVLink 1" in signing.detail and "cannot sign" in signing.detail

        link.arm()
        assert link.armed and vehicle.state.armed
        link.set_mode(FlightMode.ALT_HOLD)
        assert link.mode == FlightMode.ALT_HOLD
        if want is Dialect.APM25:
            assert link.get_param("THR_MID") == 500.0
            assert link.set_param("THR_MID", 450.0) == 450.0
        else:
            assert link.get_param("MOT_THST_HOVER") == pytest.approx(0.39)
            assert link.set_param("MOT_THST_HOVER", 0.45) == pytest.approx(0.45)
        assert link.fetch_params() == pytest.approx(vehicle.state.params)
        assert link.rc_override(RcCommand(1500, 1500, 2500, 900))
        link.disarm()
        assert not link.armed
        records = link.poll()
        assert any(isinstance(r, CommandAck) and r.command == 400 for r in records)
        link.close(release=True)

    sysid, length, chans = vehicle.state.overrides[0]
    assert sysid == 255
    assert chans == (1500, 1500, 2000, 1000, 65535, 65535, 65535, 65535)  # clamped
    # APM 2.5 must get the 8-channel MAVLink 1 form; 4.x trims trailing zeros of the v2 form.
    assert length == (18 if vehicle.profile == "apm25" else 22)
    assert wait_until(lambda: len(vehicle.state.overrides) >= 2)
    assert vehicle.state.overrides[-1][2] == (0,) * 8  # close(release=True) released them
    stats = link.stats
    assert stats.tx_messages == sum(1 for d, _, _ in tapped if d == "tx")
    assert stats.tx_bytes == sum(len(b) for d, _, b in tapped if d == "tx")
    assert stats.rx_messages == sum(1 for d, _, _ in tapped if d == "rx")
    assert stats.garbage_bytes == 0 and stats.bad_frames == 0


def test_bring_up_reaches_40_hz(vehicle: FakeVehicle) -> None:
    with VehicleLink.open(vehicle.url) as link:
        report = link.bring_up(40.0, step_hold_s=0.3, final_window_s=0.8)
        assert report.reached
        assert [s.period_ms for s in report.steps] == [100.0, 85.0, 70.0, 55.0, 40.0, 25.0]
        assert report.steps[-1].measured_hz == pytest.approx(40.0, rel=0.1)
        assert report.achieved("ATTITUDE") == pytest.approx(40.0, rel=0.1)
        assert report.steps[0].measured_hz == pytest.approx(10.0, rel=0.2)
        if link.capacity_bytes_per_s is not None:
            assert report.plan.utilisation_pct is not None and report.plan.utilisation_pct <= 80
        records = link.poll()
        assert events(records, LinkEventKind.STREAMS)
        imus = [r for r in records if isinstance(r, Imu)]
        assert imus and imus[-1].acc_b[2] == pytest.approx(-9.80665)
        ranges = [r for r in records if isinstance(r, Rangefinder)]
        assert ranges and ranges[-1].distance_m == pytest.approx(0.75) and ranges[-1].valid
        if vehicle.profile == "copter4":
            assert any(isinstance(r, Proximity) for r in records)
            assert any(isinstance(r, Radiation) and r.counts_per_s == 12.5 for r in records)
        assert "target reached" in report.summary_lines()[-1]


def test_arm_refusal_carries_the_vehicles_reason() -> None:
    v = FakeVehicle("copter4").start()
    v.state.arm_refusal = "PreArm: Throttle too high"
    try:
        with VehicleLink.open(v.url) as link:
            with pytest.raises(LinkError, match="refused to arm \\(failed\\): PreArm: Throttle"):
                link.arm(timeout_s=3.0)
            with pytest.raises(LinkError, match=r"kept refusing for 1\.5 s"):
                link.arm(timeout_s=1.5, retry=True)
            link.arm(force=True)  # 2989 bypasses the checks on 4.x
            assert link.armed
    finally:
        v.stop()


def test_force_arm_and_signing_are_refused_plainly_on_apm25() -> None:
    v = FakeVehicle("apm25").start()
    try:
        with VehicleLink.open(v.url) as link, pytest.raises(LinkUsageError, match=r"4\.x"):
            link.arm(force=True)
        with pytest.raises(LinkUsageError, match="cannot sign"):
            VehicleLink.open(v.url, signing_key=KEY)
    finally:
        v.stop()


def test_unknown_param_and_bad_name_are_one_line_errors() -> None:
    v = FakeVehicle("copter4").start()
    try:
        with VehicleLink.open(v.url) as link:
            with pytest.raises(LinkError, match="no value for parameter NOPE"):
                link.get_param("NOPE", timeout_s=0.3)
            with pytest.raises(LinkUsageError, match=r"1\.\.16 ASCII"):
                link.get_param("A_NAME_THAT_IS_TOO_LONG")
    finally:
        v.stop()


def test_watchdog_lost_then_regained_after_tcp_reopen() -> None:
    v = FakeVehicle("copter4").start()
    try:
        link = VehicleLink.open(v.url)
        link.poll()
        v.crash()
        records = poll_until(link, lambda rs: events(rs, LinkEventKind.LOST), timeout_s=4.0)
        lost = events(records, LinkEventKind.LOST)[0]
        assert link.lost
        assert events(records, LinkEventKind.RECONNECTING)
        # proof of life is any frame: lost 1.5 s after the last one, whatever its type
        assert 1.5 <= lost.t_s - link.last_rx_s <= 2.0
        start = time.monotonic()
        link.poll()
        assert time.monotonic() - start < 0.05  # reconnect attempts never block poll()
        v.restart()
        records = poll_until(link, lambda rs: events(rs, LinkEventKind.REGAINED), timeout_s=6.0)
        assert not link.lost
        assert link.stats.reconnects >= 1
        link.close()
    finally:
        v.stop()


def test_silence_declares_lost_between_1_5_and_2_s() -> None:
    v = FakeVehicle("apm25").start()
    try:
        with VehicleLink.open(v.url) as link:
            hb_t = [r.t_s for r in poll_until(
                link, lambda rs: any(type(r).__name__ == "Heartbeat" for r in rs), 3.0)
                if type(r).__name__ == "Heartbeat"]
            v.paused.set()
            records = poll_until(link, lambda rs: events(rs, LinkEventKind.LOST), timeout_s=4.0)
            last_hb = max([*hb_t, *(r.t_s for r in records if type(r).__name__ == "Heartbeat")])
            lost = events(records, LinkEventKind.LOST)[0]
            assert 1.5 <= lost.t_s - last_hb <= 2.0  # this vehicle sends heartbeats only
            assert last_hb == link.last_heartbeat_s <= link.last_rx_s
            v.paused.clear()
            poll_until(link, lambda rs: events(rs, LinkEventKind.REGAINED), timeout_s=3.0)
    finally:
        v.stop()


def test_garbage_bytes_are_counted_not_fatal() -> None:
    v = FakeVehicle("copter4", serial=True).start()
    try:
        with VehicleLink.open(v.url) as link:
            before = link.stats
            v.inject(bytes(range(1, 200)))
            v.inject(b"\xfd\x09\x00\x00\x00\x01\x01\x00\x00\x00" + bytes(11))  # bad CRC
            v.inject(bytes(range(1, 200)))
            poll_until(link, lambda rs: link.stats.garbage_bytes - before.garbage_bytes >= 398)
            assert link.stats.bad_frames >= 1
            link.arm()  # the link still works
    finally:
        v.stop()


def test_signed_link_works_and_a_strangers_unsigned_frames_are_refused() -> None:
    v = FakeVehicle("copter4", signing_key=KEY).start()
    try:
        with VehicleLink.open(v.url, signing_key=KEY) as link:
            assert link.signing
            link.arm()
            link.set_mode(FlightMode.LAND)
            assert link.mode == FlightMode.LAND
            refused_before = link.stats.signature_refusals
            # A stranger on the same port: unsigned frames claiming to be the vehicle.
            stranger = mavlink.MAVLink(None, 1, 1)
            fake = stranger.heartbeat_encode(2, 3, 81, int(FlightMode.STABILIZE), 3, 3)
            v.inject(bytes(fake.pack(stranger)))
            poll_until(link, lambda rs: link.stats.signature_refusals > refused_before)
            assert link.mode == FlightMode.LAND  # the forged heartbeat changed nothing
            link.close(release=True)
        # The station signed everything it sent, down to the release on close: the vehicle
        # refused nothing of ours.
        assert wait_until(lambda: "RC_CHANNELS_OVERRIDE" in v.state.rx_types)
        assert v.state.refused == 0
    finally:
        v.stop()


def test_signing_key_the_vehicle_does_not_use_fails_clearly() -> None:
    v = FakeVehicle("copter4").start()
    try:
        with pytest.raises(LinkError, match="no frames signed with this key"):
            VehicleLink.open(v.url, signing_key=KEY, wait_heartbeat_s=1.5)
    finally:
        v.stop()


def test_unreachable_port_fails_fast_with_one_line() -> None:
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    start = time.monotonic()
    with pytest.raises(LinkError, match="connection refused") as info:
        VehicleLink.open(f"tcp:127.0.0.1:{port}")
    assert time.monotonic() - start < 1.0
    assert "\n" not in str(info.value) and info.value.exit_code == 1


def test_missing_busy_serial_and_silent_peer_are_clear_errors() -> None:
    with pytest.raises(LinkError, match="no such device"):
        VehicleLink.open("/dev/does-not-exist-quadgcs")
    v = FakeVehicle("apm25", serial=True).start()
    try:
        with VehicleLink.open(v.url), pytest.raises(LinkError, match="busy"):
            VehicleLink.open(v.url)
    finally:
        v.stop()
    server = socket.socket()
    server.bind(("127.0.0.1", 0))
    server.listen(1)
    try:
        with pytest.raises(LinkError, match=r"no vehicle heartbeat within 0\.3 s"):
            VehicleLink.open(f"tcp:127.0.0.1:{server.getsockname()[1]}", wait_heartbeat_s=0.3)
    finally:
        server.close()


def test_a_crash_inside_the_context_manager_leaves_the_overrides_as_they_were() -> None:
    # releasing is the supervisor's decision: on 4.x it drops the throttle to the radio's
    # minimum, so a link that goes away on an exception must not do it by itself
    v = FakeVehicle("apm25").start()
    try:
        with pytest.raises(RuntimeError), VehicleLink.open(v.url) as link:
            link.rc_override(RcCommand(throttle_us=1400))
            raise RuntimeError("loop crashed")
        assert wait_until(lambda: len(v.state.overrides) >= 1)
        assert all(chans[2] == 1400 for _sys, _n, chans in v.state.overrides)
        link.close(release=True)  # idempotent: closed already, nothing more is sent
        assert all(chans[2] == 1400 for _sys, _n, chans in v.state.overrides)
    finally:
        v.stop()


def test_udpin_link_answers_whoever_speaks() -> None:
    with _UdpVehicle() as (url, peer):
        link = VehicleLink.open(url, wait_heartbeat_s=3.0)
        try:
            assert link.dialect is Dialect.COPTER4
            link.rc_override(RcCommand())
            deadline = time.monotonic() + 2
            got = b""
            while time.monotonic() < deadline and got == b"":
                link.poll()
                try:
                    got = peer.recv(300)
                except BlockingIOError:
                    link._wait_readable(time.monotonic() + 0.01)
            assert got[:1] == b"\xfd"
        finally:
            link.close()


class _UdpVehicle:
    """A vehicle that sends heartbeats to a udpin station port."""

    def __enter__(self):
        probe = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
        probe.close()
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.setblocking(False)
        mav = mavlink.MAVLink(None, 1, 1)
        self.frame = bytes(mav.heartbeat_encode(2, 3, 81, 0, 3, 3).pack(mav))
        self.port = port
        self.stop = threading.Event()

        def beat() -> None:
            while not self.stop.wait(0.05):
                self.sock.sendto(self.frame, ("127.0.0.1", port))

        self.thread = threading.Thread(target=beat, daemon=True)
        self.thread.start()
        return f"udpin:127.0.0.1:{port}", self.sock

    def __exit__(self, *exc) -> None:
        self.stop.set()
        self.thread.join()
        self.sock.close()



def test_udpout_link_reaches_a_vehicle_that_answers_the_sender() -> None:
    vehicle = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    vehicle.bind(("127.0.0.1", 0))
    vehicle.settimeout(0.05)
    mav = mavlink.MAVLink(None, 1, 1)
    heartbeat = bytes(mav.heartbeat_encode(2, 3, 81, 0, 3, 3).pack(mav))
    stop = threading.Event()
    heard: list[bytes] = []

    def serve() -> None:
        # Like a UDP server endpoint: quiet until a station speaks, then answers it.
        while not stop.is_set():
            try:
                data, addr = vehicle.recvfrom(512)
            except TimeoutError:
                continue
            heard.append(data)
            vehicle.sendto(heartbeat, addr)

    thread = threading.Thread(target=serve, daemon=True)
    thread.start()
    try:
        url = f"udpout:127.0.0.1:{vehicle.getsockname()[1]}"
        with VehicleLink.open(url, wait_heartbeat_s=3.0) as link:
            assert link.dialect is Dialect.COPTER4 and link.target_system == 1
        assert heard and heard[0][0] == 0xFE  # the station's greeting, before it knew
    finally:
        stop.set()
        thread.join()
        vehicle.close()


def test_a_backlog_is_worked_off_over_several_polls() -> None:
    v = FakeVehicle("copter4", companion=False).start()
    try:
        with VehicleLink.open(v.url) as link:
            link.poll()
            sender = mavlink.MAVLink(None, 1, 1)
            frames = []
            for k in range(3000):  # ≈ 120 kB: several seconds of a fast serial link at once
                msg = sender.attitude_encode(k, 0.1, 0.0, 0.0, 0.0, 0.0, 0.0)
                frames.append(bytes(msg.pack(sender)))
                sender.seq = (sender.seq + 1) % 256
            before = link.stats.rx_bytes
            v.inject(b"".join(frames))
            sizes: list[int] = []
            deadline = time.monotonic() + 10
            got = 0
            while got < 3000 and time.monotonic() < deadline:
                n = sum(1 for r in link.poll() if type(r).__name__ == "Attitude")
                got += n
                if n:
                    sizes.append(n)
                link._wait_readable(time.monotonic() + 0.005)
            assert got == 3000
            frame_bytes = len(frames[-1])
            assert max(sizes) * frame_bytes <= 16384  # one poll parses one read budget at most
            assert link.stats.rx_bytes - before >= sum(map(len, frames))
    finally:
        v.stop()


def test_a_vanished_serial_device_is_retried_without_blocking_poll() -> None:
    v = FakeVehicle("apm25", serial=True).start()
    link = VehicleLink.open(v.url)
    try:
        link.poll()
        v.stop()  # the far end of the serial line is gone (USB adapter pulled)
        records = poll_until(
            link,
            lambda rs: events(rs, LinkEventKind.RECONNECTING) and events(rs, LinkEventKind.LOST),
            timeout_s=4.0,
        )
        assert "reopening" in events(records, LinkEventKind.RECONNECTING)[0].detail
        slowest = 0.0
        for _ in range(50):  # reopen attempts fail fast and never stall the loop
            start = time.monotonic()
            link.poll()
            slowest = max(slowest, time.monotonic() - start)
            link._wait_readable(time.monotonic() + 0.01)
        assert slowest < 0.05
        assert not link.rc_override(RcCommand())  # nothing to send on: dropped and counted
        assert link.stats.tx_dropped >= 1
    finally:
        link.close()
