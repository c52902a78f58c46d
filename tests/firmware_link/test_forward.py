"""MAVLink forwarding: other ground stations on real TCP and UDP sockets beside a vehicle link."""

from __future__ import annotations

import socket
import time
from collections.abc import Callable, Iterator

import pytest

from firmware_link import (
    Forwarder,
    LinkError,
    LinkUsageError,
    VehicleLink,
)
from firmware_link.forward_peers import TCP_BACKLOG_BYTES, parse_forward_url
from firmware_link.protocol import mavlink
from firmware_link.records import LinkEvent, LinkEventKind, RcCommand
from firmware_link.signing import signing_timestamp
from tests.firmware_link.peer import FakeVehicle
from worldfile import key_from_passphrase

KEY = key_from_passphrase("quadgcs test key")
OTHER_GCS = 254  # the forwarded station's system id, so the vehicle can tell who sent what


class OtherStation:
    """A ground station (as MAVProxy or QGroundControl would be) on a TCP or UDP socket."""

    def __init__(self, sock: socket.socket, key: bytes | None = None,
                 to: tuple[str, int] | None = None) -> None:
        self.sock = sock
        self.sock.setblocking(False)
        self.to = to
        self.mav = mavlink.MAVLink(None, OTHER_GCS, 230)
        self.mav.robust_parsing = True
        self.got: list = []
        if key is not None:
            self.mav.signing.secret_key = key
            self.mav.signing.sign_outgoing = True
            self.mav.signing.link_id = 3
            self.mav.signing.timestamp = signing_timestamp(time.time())

    @classmethod
    def tcp(cls, port: int, key: bytes | None = None) -> OtherStation:
        return cls(socket.create_connection(("127.0.0.1", port), timeout=2.0), key)

    def send(self, msg) -> None:
        frame = bytes(msg.pack(self.mav))
        self.mav.seq = (self.mav.seq + 1) % 256
        self.send_bytes(frame)

    def send_bytes(self, data: bytes) -> None:
        if self.to is not None:
            self.sock.sendto(data, self.to)
        else:
            self.sock.sendall(data)

    def read(self) -> None:
        try:
            data = self.sock.recv(65536)
        except BlockingIOError:
            return
        for m in self.mav.parse_buffer(data) or ():
            if m.get_type() != "BAD_DATA":
                self.got.append(m)

    def close(self) -> None:
        self.sock.close()


def run_until(link: VehicleLink, done: Callable[[], bool], *stations: OtherStation,
              each: Callable[[], None] | None = None, timeout_s: float = 5.0) -> list:
    """Poll the link (and read the stations) until `done()`; the link's records meanwhile."""
    records: list = []
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if each is not None:
            each()
        records.extend(link.poll())
        for s in stations:
            s.read()
        if done():
            return records
        link._wait_readable(time.monotonic() + 0.005)
    raise AssertionError(f"condition not met in {timeout_s} s")


def notes(records: list) -> list[str]:
    return [r.detail for r in records if isinstance(r, LinkEvent)
            and r.kind is LinkEventKind.FORWARD]


@pytest.fixture
def vehicle() -> Iterator[FakeVehicle]:
    v = FakeVehicle("copter4").start()
    yield v
    v.stop()


@pytest.fixture
def forwarder() -> Iterator[Forwarder]:
    fwd = Forwarder.open(["tcpin:127.0.0.1:0"])
    yield fwd
    fwd.close()


def tcp_port(fwd: Forwarder) -> int:
    return int(fwd.urls[0].rsplit(":", 1)[1])


@pytest.fixture
def linked(vehicle: FakeVehicle,
           forwarder: Forwarder) -> Iterator[tuple[VehicleLink, OtherStation]]:
    """A link to the vehicle through the forwarder, and another station on its TCP port."""
    link = VehicleLink.open(vehicle.url, forward=forwarder.port(None))
    station = OtherStation.tcp(tcp_port(forwarder))
    yield link, station
    station.close()
    link.close()


@pytest.mark.parametrize("url, words", [
    ("tcp:127.0.0.1:5760", "not understood"),
    ("udpout:127.0.0.1", "missing HOST:PORT"),
    ("tcpin:127.0.0.1:port", "is not a number"),
    ("udpin:127.0.0.1:70000", "is not a number in 0..65535"),
    ("udpout:127.0.0.1:0", "port 0 cannot be sent to"),
])
def test_a_bad_forward_url_is_one_line_naming_it(url: str, words: str) -> None:
    with pytest.raises(LinkUsageError) as info:
        parse_forward_url(url)
    text = str(info.value)
    assert words in text and url in text and "\n" not in text


def test_a_port_already_taken_is_one_line(forwarder: Forwarder) -> None:
    taken = forwarder.urls[0]
    with pytest.raises(LinkError) as info:
        Forwarder.open([taken])
    assert taken in str(info.value) and "\n" not in str(info.value)


def test_vehicle_frames_go_out_unchanged_and_a_stations_param_set_reaches_the_vehicle(
        vehicle: FakeVehicle, forwarder: Forwarder) -> None:
    tapped: set[bytes] = set()
    link = VehicleLink.open(vehicle.url, forward=forwarder.port(None),
                            on_raw=lambda d, _t, frame: tapped.add(frame) if d == "rx" else None)
    station = OtherStation.tcp(tcp_port(forwarder))
    try:
        run_until(link, lambda: sum(m.get_type() == "HEARTBEAT" for m in station.got) >= 2,
                  station)
        # byte for byte what the link itself received, sequence numbers and all
        assert all(bytes(m.get_msgbuf()) in tapped for m in station.got)
        assert {m.get_srcSystem() for m in station.got} == {1}
        station.send(station.mav.param_set_encode(1, 1, b"ATC_RAT_RLL_P", 0.2, 9))
        run_until(link, lambda: abs(vehicle.state.params["ATC_RAT_RLL_P"] - 0.2) < 1e-6
                  and any(m.get_type() == "PARAM_VALUE" for m in station.got), station)
        value = [m for m in station.got if m.get_type() == "PARAM_VALUE"][-1]
        assert value.param_id == "ATC_RAT_RLL_P" and abs(value.param_value - 0.2) < 1e-6
        assert forwarder.stats.stations == 1 and forwarder.stats.to_vehicle >= 1
    finally:
        station.close()
        link.close()


def test_a_stations_overrides_are_refused_while_the_link_writes_the_sticks(
        vehicle: FakeVehicle, forwarder: Forwarder,
        linked: tuple[VehicleLink, OtherStation]) -> None:
    link, station = linked
    theirs = station.mav.rc_channels_override_encode(1, 1, 0, 0, 1800, 0, 0, 0, 0, 0)
    ours = RcCommand(throttle_us=1300)

    def both_write() -> None:
        link.rc_override(ours)
        station.send(theirs)

    def vehicle_saw(sysid: int) -> bool:
        return any(s == sysid for s, _n, _c in vehicle.state.overrides)

    records = run_until(link, lambda: forwarder.stats.refused_overrides >= 20, station,
                        each=both_write)
    assert vehicle_saw(255) and not vehicle_saw(OTHER_GCS)
    # reported once, not once per frame
    assert len(notes(records)) == 1 and "RC override refused" in notes(records)[0]
    link.release_overrides()
    run_until(link, lambda: vehicle_saw(OTHER_GCS), station,
              each=lambda: station.send(theirs))
    chans = [c for s, _n, c in vehicle.state.overrides if s == OTHER_GCS]
    assert chans[-1][2] == 1800  # byte for byte what the other station sent


def test_a_silent_link_lets_nothing_of_a_station_through(
        vehicle: FakeVehicle, forwarder: Forwarder,
        linked: tuple[VehicleLink, OtherStation]) -> None:
    link, station = linked
    gcs_hb = station.mav.heartbeat_encode(6, 8, 0, 0, 4)
    run_until(link, lambda: forwarder.stats.stations == 1, station)
    link.set_gcs_heartbeat(False)
    before = vehicle.state.gcs_heartbeats
    # the other station's heartbeats would reset the failsafe the silence is for
    run_until(link, lambda: forwarder.stats.refused_silent >= 10, station,
              each=lambda: station.send(gcs_hb))
    assert vehicle.state.gcs_heartbeats == before
    link.set_gcs_heartbeat(True)
    run_until(link, lambda: vehicle.state.gcs_heartbeats >= before + 3, station,
              each=lambda: station.send(gcs_hb))


def test_signed_link_keeps_signatures_and_refuses_a_stations_unsigned_frames() -> None:
    vehicle = FakeVehicle("copter4", signing_key=KEY).start()
    fwd = Forwarder.open(["tcpin:127.0.0.1:0"])
    link = VehicleLink.open(vehicle.url, signing_key=KEY, forward=fwd.port(None))
    plain = OtherStation.tcp(tcp_port(fwd))
    signed = OtherStation.tcp(tcp_port(fwd), key=KEY)
    try:
        assert link.signing
        run_until(link, lambda: len(signed.got) > 10, signed, plain)
        assert all(m._signed for m in signed.got)  # the vehicle's own signatures, checked
        plain.send(plain.mav.param_set_encode(1, 1, b"ATC_RAT_RLL_P", 0.3, 9))
        run_until(link, lambda: fwd.stats.refused_unsigned >= 1, signed, plain)
        signed.send(signed.mav.param_set_encode(1, 1, b"ATC_RAT_RLL_P", 0.25, 9))
        run_until(link, lambda: abs(vehicle.state.params["ATC_RAT_RLL_P"] - 0.25) < 1e-6,
                  signed, plain)
        assert vehicle.state.refused == 0  # nothing unsigned got to the vehicle
    finally:
        plain.close()
        signed.close()
        link.close()
        fwd.close()
        vehicle.stop()


def test_udp_stations_out_and_in(vehicle: FakeVehicle) -> None:
    listener = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    listener.bind(("127.0.0.1", 0))
    fwd = Forwarder.open([f"udpout:127.0.0.1:{listener.getsockname()[1]}", "udpin:127.0.0.1:0"])
    udpin_port = int(fwd.urls[1].rsplit(":", 1)[1])
    link = VehicleLink.open(vehicle.url, forward=fwd.port(None))
    out_station = OtherStation(listener)
    in_sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    in_station = OtherStation(in_sock, to=("127.0.0.1", udpin_port))
    try:
        run_until(link, lambda: len(out_station.got) > 5, out_station)
        assert in_station.got == []  # udpin answers only a station that spoke
        in_station.send(in_station.mav.heartbeat_encode(6, 8, 0, 0, 4))
        run_until(link, lambda: len(in_station.got) > 5, out_station, in_station)
        assert fwd.stats.stations == 2
    finally:
        for s in (out_station, in_station):
            s.close()
        link.close()
        fwd.close()


def test_garbage_from_a_station_is_counted_and_its_next_frame_still_passes(
        vehicle: FakeVehicle, forwarder: Forwarder,
        linked: tuple[VehicleLink, OtherStation]) -> None:
    link, station = linked
    frame = bytearray(station.mav.param_set_encode(1, 1, b"ATC_RAT_RLL_P", 0.4, 9)
                      .pack(station.mav))
    frame[-1] ^= 0xFF  # a bad CRC
    station.send_bytes(bytes(frame) + b"\x00\x17garbage")
    station.send(station.mav.param_set_encode(1, 1, b"ATC_RAT_RLL_P", 0.15, 9))
    run_until(link, lambda: abs(vehicle.state.params["ATC_RAT_RLL_P"] - 0.15) < 1e-6, station)
    assert forwarder.stats.bad_frames >= 1


def test_a_station_that_stops_reading_costs_dropped_frames_not_a_blocked_loop(
        forwarder: Forwarder) -> None:
    port = forwarder.port(None)
    stalled = socket.socket()
    stalled.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
    stalled.connect(("127.0.0.1", tcp_port(forwarder)))
    try:
        deadline = time.monotonic() + 3.0
        while forwarder.stats.stations == 0 and time.monotonic() < deadline:
            port.from_stations(now_s=0.0, sticks_owned=False, silent=False, signing_key=None)
        frame = bytes(300)
        for _ in range(4 * TCP_BACKLOG_BYTES // len(frame)):
            port.to_stations(frame)  # must return every time: the socket is non-blocking
        assert forwarder.stats.to_stations_dropped > 0
    finally:
        stalled.close()


def test_several_vehicles_share_a_forwarder_by_target_system(forwarder: Forwarder) -> None:
    one, two = forwarder.port(1), forwarder.port(2)
    station = OtherStation.tcp(tcp_port(forwarder))
    try:
        station.send(station.mav.param_set_encode(2, 1, b"ATC_RAT_RLL_P", 0.2, 9))
        station.send(station.mav.heartbeat_encode(6, 8, 0, 0, 4))
        got: dict[int, list[bytes]] = {1: [], 2: []}
        deadline = time.monotonic() + 3.0
        while len(got[2]) < 2 and time.monotonic() < deadline:
            for sysid, p in ((1, one), (2, two)):
                frames, _ = p.from_stations(now_s=0.0, sticks_owned=False, silent=False,
                                            signing_key=None)
                got[sysid].extend(frames)
        decoded = {s: [mavlink.MAVLink(None).parse_char(f).get_type() for f in fs]
                   for s, fs in got.items()}
        assert decoded[2] == ["PARAM_SET", "HEARTBEAT"]
        assert decoded[1] == ["HEARTBEAT"]
    finally:
        station.close()


def test_a_stations_stream_rate_requests_are_refused_and_its_commands_pass(
        vehicle: FakeVehicle, forwarder: Forwarder,
        linked: tuple[VehicleLink, OtherStation]) -> None:
    link, station = linked
    run_until(link, lambda: forwarder.stats.stations == 1, station)
    rates_before = dict(vehicle.state.rates_hz)
    # MAVProxy's default: every stream at 4 Hz, which would starve a 40 Hz loop
    station.send(station.mav.request_data_stream_encode(1, 1, 0, 4, 1))
    station.send(station.mav.command_long_encode(1, 1, 511, 0, 30, 250000, 0, 0, 0, 0, 0))
    station.send(station.mav.command_long_encode(1, 1, 512, 0, 148, 0, 0, 0, 0, 0, 0))
    records = run_until(
        link, lambda: any(m.get_type() == "AUTOPILOT_VERSION" for m in station.got), station)
    assert forwarder.stats.refused_streams == 2
    assert vehicle.state.rates_hz == rates_before
    assert any("stream-rate request refused" in n for n in notes(records))
