"""What the SITL puts on a link: MAVLink 1 base payloads, one capped ground-truth message, the
real firmware's stream sets and byte rates, and what a station's fast request costs on a
115200-baud serial port (counted on the simulated clock)."""

from __future__ import annotations

import math
import time
from collections import Counter

import pytest
from pymavlink.dialects.v10 import ardupilotmega as mavlink_v1

from sitl.autopilot import Profile
from sitl.link import Stream
from sitl.link import telemetry as tm
from sitl.link.codec import SIGNING_EPOCH_UNIX_S, MavCodec, mavlink
from sitl.link.server import SERIAL_TRUTH_MAX_RATE_HZ
from sitl.link.telemetry import EARTH_RADIUS_M
from sitl.simulation import MemoryLink, Simulation
from tests.sitl.flight_helpers import big_room
from tests.sitl.gcs_peer import MemoryGcs

SERIAL_BYTES_PER_S = 11520.0  # 115200 baud, 8N1
V1_STX, V2_STX = 0xFE, 0xFD
V1_OVERHEAD, V2_OVERHEAD, SIGNATURE = 8, 12, 13

# The station's 40 Hz request on APM 2.5 (REQUEST_DATA_STREAM groups, whole Hz).
APM25_RATES_HZ = {
    Stream.EXTRA1: 40,  # ATTITUDE (+ ground truth)
    Stream.RAW_SENSORS: 40,  # RAW_IMU, SCALED_PRESSURE
    Stream.EXTRA3: 40,  # RANGEFINDER
    Stream.EXTRA2: 10,  # VFR_HUD
    Stream.EXTENDED_STATUS: 2,  # SYS_STATUS
    Stream.RC_CHANNELS: 5,  # RC_CHANNELS_RAW, SERVO_OUTPUT_RAW
}


def split_frames(data: bytes) -> list[bytes]:
    """Cut a byte stream into whole MAVLink 1/2 frames (the stream must start on a frame)."""
    frames, i = [], 0
    while i < len(data):
        stx, plen = data[i], data[i + 1]
        if stx == V1_STX:
            size = plen + V1_OVERHEAD
        else:
            assert stx == V2_STX, f"byte {i}: not a frame start"
            size = plen + V2_OVERHEAD + (SIGNATURE if data[i + 2] & 1 else 0)
        frames.append(data[i : i + size])
        i += size
    assert i == len(data)
    return frames


def _v1_msg_id(frame: bytes) -> int:
    return frame[5]


def _serial_link(
    sim: Simulation, truth_max_rate_hz: float = SERIAL_TRUTH_MAX_RATE_HZ
) -> MemoryLink:
    rt = sim.vehicle(1)
    return MemoryLink(rt, rt.add_channel(1, "serial", truth_max_rate_hz))


def _request(gcs: MemoryGcs, rates: dict[Stream, int]) -> None:
    gcs.heartbeat()
    for stream, hz in rates.items():
        gcs.send(mavlink.MAVLink_request_data_stream_message(1, 1, int(stream), hz, 1))


def _collect(sim: Simulation, link: MemoryLink, seconds: float) -> bytes:
    out = bytearray()
    end = sim.t_s + seconds
    while sim.t_s + 1e-9 < end:
        sim.tick()
        out += link.read()
    return bytes(out)


def _settled_apm25(link_of: str) -> tuple[Simulation, MemoryGcs]:
    sim = Simulation(big_room(), Profile.APM25, 1, seed=3)
    link = _serial_link(sim) if link_of == "serial" else sim.memory_link(1)
    gcs = MemoryGcs(sim, link, mavlink1=True)
    _request(gcs, APM25_RATES_HZ)
    gcs.run(1.0)  # past the first burst of parameters and texts
    return sim, gcs


def test_every_apm25_frame_carries_only_its_mavlink1_base_payload() -> None:
    sim, gcs = _settled_apm25("serial")
    frames = split_frames(_collect(sim, gcs.link, 2.0))
    kinds = Counter()
    for f in frames:
        assert f[0] == V1_STX
        cls = mavlink_v1.mavlink_map[_v1_msg_id(f)]
        assert f[1] == cls.unpacker.size, f"{cls.msgname}: {f[1]} B payload"
        kinds[cls.msgname] += 1
    assert {"ATTITUDE", "RAW_IMU", "RANGEFINDER", "DISTANCE_SENSOR", "SIM_STATE"} <= set(kinds)
    # a v1-only parser (no extensions at all) reads the companion's frames back
    parser = mavlink_v1.MAVLink(None)
    parser.robust_parsing = True
    prox = [
        m
        for m in parser.parse_buffer(b"".join(frames)) or []
        if m.get_type() == "DISTANCE_SENSOR"
    ]
    assert len(prox) == kinds["DISTANCE_SENSOR"]
    assert {m.orientation for m in prox} == {0, 2, 4, 6, 24, 25}
    assert all(m.max_distance == 50 for m in prox)
    assert all(len(f) == 14 + V1_OVERHEAD for f in frames if _v1_msg_id(f) == 132)


def test_mavlink1_codec_cuts_extensions_and_a_v2_parser_zero_fills_them() -> None:
    tx = MavCodec(1, 158, mavlink1_only=True)
    msg = mavlink.MAVLink_distance_sensor_message(
        7, 2, 50, 33, 2, 3, 25, 0, 1.5, 2.5, [1.0, 0.0, 0.0, 0.0], 90
    )
    frame = tx.encode(msg)
    assert (frame[0], frame[1], len(frame)) == (V1_STX, 14, 22)
    rx = MavCodec(255, 190, mavlink1_only=True)
    (back,) = rx.decode(frame)
    assert (back.time_boot_ms, back.current_distance, back.orientation) == (7, 33, 25)
    assert (back.horizontal_fov, back.signal_quality) == (0.0, 0)
    mocap = MavCodec(200, 1, mavlink1_only=True).encode(
        mavlink.MAVLink_att_pos_mocap_message(1, [1.0, 0.0, 0.0, 0.0], 1.0, 2.0, -0.5, [0.0] * 21)
    )
    assert mocap[1] == 36  # covariance is a MAVLink 2 extension
    v2 = MavCodec(1, 158, mavlink1_only=False).encode(msg)
    assert v2[0] == V2_STX and v2[1] == 39  # MAVLink 2 keeps the extensions


def test_serial_link_caps_ground_truth_while_another_link_keeps_full_rate() -> None:
    sim = Simulation(big_room(), Profile.APM25, 1, seed=4)
    full = MemoryGcs(sim, sim.memory_link(1), mavlink1=True)
    capped = MemoryGcs(sim, _serial_link(sim), mavlink1=True)
    for gcs in (full, capped):
        _request(gcs, {Stream.EXTRA1: 40})
    full.run(0.5, every_tick=capped.poll)
    capped.poll()
    full.received.clear()
    capped.received.clear()
    full.run(2.0, every_tick=capped.poll)
    capped.poll()

    def count(gcs: MemoryGcs, kind: str) -> int:
        return len(gcs.of_type(kind, gcs.received))

    # 40 Hz asked of 3.2.1 arrives at 25 Hz (50 / (int(50 / 40) + 1))
    assert count(full, "ATTITUDE") == pytest.approx(50, abs=2)
    assert count(capped, "ATTITUDE") == pytest.approx(50, abs=2)
    assert count(full, "SIM_STATE") == pytest.approx(50, abs=2)
    assert count(capped, "SIM_STATE") == pytest.approx(2.0 * SERIAL_TRUTH_MAX_RATE_HZ, abs=1)
    assert count(full, "SIMSTATE") == count(capped, "SIMSTATE") == 0


def test_truth_cap_also_bounds_set_message_interval() -> None:
    sim = Simulation(big_room(), Profile.COPTER4, 1, seed=5)
    ch = _serial_link(sim, 10.0).channel
    assert ch.streams.set_interval("SIM_STATE", 20_000)  # 50 Hz asked
    assert ch.streams.interval_s("SIM_STATE") == pytest.approx(0.1)
    assert ch.streams.set_interval("ATTITUDE", 25_000)
    assert ch.streams.interval_s("ATTITUDE") == pytest.approx(0.025)
    assert not ch.streams.set_interval("SIMSTATE", 25_000)  # not streamed at all
    with pytest.raises(ValueError):
        _serial_link(sim, 0.0)


def _bytes_per_s(profile: Profile, signing_key: bytes | None = None) -> tuple[float, Counter]:
    """Bytes/s a serial channel emits at the station's 40 Hz request, on the simulated clock."""
    sim = Simulation(big_room(), profile, 1, seed=6, signing_key=signing_key)
    link = _serial_link(sim)
    gcs = MemoryGcs(sim, link, mavlink1=profile is Profile.APM25)
    if signing_key is not None:
        gcs.mav.signing.secret_key = signing_key
        gcs.mav.signing.sign_outgoing = True
        gcs.mav.signing.timestamp = int((time.time() - SIGNING_EPOCH_UNIX_S) * 100_000)
    if profile is Profile.APM25:
        _request(gcs, APM25_RATES_HZ)
    else:
        gcs.heartbeat()
        for name, hz in (
            ("ATTITUDE", 40),
            ("RAW_IMU", 40),
            ("DISTANCE_SENSOR", 40),
            ("VFR_HUD", 10),
            ("SYS_STATUS", 2),
            ("SCALED_PRESSURE", 10),
            ("RC_CHANNELS", 5),
            ("SERVO_OUTPUT_RAW", 5),
            ("SIM_STATE", 10),
        ):
            msg_id = getattr(mavlink, f"MAVLINK_MSG_ID_{name}")
            gcs.command(1, 511, msg_id, 1e6 / hz)
    gcs.run(1.0)
    seconds = 4.0
    data = _collect(sim, link, seconds)
    sizes: Counter = Counter()
    for f in split_frames(data):
        msg_id = f[5] if f[0] == V1_STX else int.from_bytes(f[7:10], "little")
        sizes[mavlink.mavlink_map[msg_id].msgname] += len(f)
    return len(data) / seconds, sizes


def test_apm25_40_hz_request_gets_25_hz_and_the_whole_groups_near_80_percent() -> None:
    """3.2.1 streams no group faster than 25 Hz, and each group brings all its messages
    (EXTRA1: ATTITUDE, AHRS2 and the truth; EXTRA3: AHRS, HWSTATUS, SYSTEM_TIME, RANGEFINDER,
    TERRAIN_REPORT, ...): the station's 40 Hz set fills about 79 % of the port."""
    rate, sizes = _bytes_per_s(Profile.APM25)
    assert 0.7 * SERIAL_BYTES_PER_S <= rate <= 0.85 * SERIAL_BYTES_PER_S, dict(sizes)
    assert sizes["ATTITUDE"] == pytest.approx(4 * 25 * 36, rel=0.02)  # 25 Hz, not 40
    for name in ("AHRS2", "AHRS", "HWSTATUS", "SYSTEM_TIME", "TERRAIN_REPORT", "RANGEFINDER"):
        assert sizes[name] > 0, name
    assert sizes["DISTANCE_SENSOR"] == pytest.approx(4 * 60 * 22, rel=0.02)  # the companion


def test_copter4_unsigned_control_set_at_40_hz_fits_80_percent() -> None:
    rate, sizes = _bytes_per_s(Profile.COPTER4)
    assert rate <= 0.8 * SERIAL_BYTES_PER_S, dict(sizes)
    assert sizes["ATTITUDE"] == pytest.approx(4 * 40 * 40, rel=0.02)


def test_copter4_signed_40_hz_does_not_fit_the_80_percent_budget() -> None:
    """Physics, not a bug: 13 signature bytes on ≈ 220 frames/s take the 40 Hz set from ≈ 68 %
    to ≈ 93 % of the port, so a signed copter4 on 115200 baud must run its fast streams slower."""
    key = bytes(range(32))
    unsigned, _ = _bytes_per_s(Profile.COPTER4)
    signed, sizes = _bytes_per_s(Profile.COPTER4, key)
    assert sizes["ATTITUDE"] == pytest.approx(4 * 40 * (40 + SIGNATURE), rel=0.02)
    frames_per_s = (signed - unsigned) / SIGNATURE
    assert 200 <= frames_per_s <= 240
    assert 0.8 * SERIAL_BYTES_PER_S < signed < SERIAL_BYTES_PER_S


@pytest.mark.parametrize("profile", [Profile.APM25, Profile.COPTER4])
def test_truth_position_survives_the_frame_to_the_centimetre(profile: Profile) -> None:
    """SIM_STATE's MAVLink 1 payload has float32 degrees only; at the default origin they still
    resolve far below a centimetre."""
    sim = Simulation(big_room(), profile, 1, seed=7)
    view = sim.vehicle(1).view
    view.cache.truth_pos_n = (13.217, -17.561, -1.234)
    frame = MavCodec(1, 1, profile is Profile.APM25).encode(tm.sim_state(view))
    (msg,) = MavCodec(255, 190, profile is Profile.APM25).decode(frame)
    o = view.origin
    north = math.radians(msg.lat - o.lat_deg) * EARTH_RADIUS_M
    east = math.radians(msg.lon - o.lon_deg) * EARTH_RADIUS_M * math.cos(math.radians(o.lat_deg))
    assert north == pytest.approx(13.217, abs=0.01)
    assert east == pytest.approx(-17.561, abs=0.01)
    assert msg.alt - o.alt_amsl_m == pytest.approx(1.234, abs=0.001)


# Bytes/s of the vehicle's own frames (compid 1) measured in the fixture tlogs: 4.7-dev from
# 6 to 18 s (REQUEST_DATA_STREAM ALL 10 Hz), 3.2.1 from 20 to 80 s (ALL 10 Hz, then groups
# 1, 2, 3, 10, 11, 12 at 25 Hz), both over TCP.
FIXTURE_BYTES_PER_S = {Profile.COPTER4: 9321.0, Profile.APM25: 8180.0}


@pytest.mark.parametrize("profile", [Profile.APM25, Profile.COPTER4])
def test_all_streams_cost_what_the_real_firmware_sends(profile: Profile) -> None:
    sim = Simulation(big_room(), profile, 1, seed=8)
    gcs = MemoryGcs(sim, sim.memory_link(1), mavlink1=profile is Profile.APM25)
    _request(gcs, {Stream.ALL: 10})
    if profile is Profile.APM25:
        _request(gcs, {s: 25 for s in (1, 2, 3, 10, 11, 12)})
    gcs.run(4.0)
    data = _collect(sim, gcs.link, 10.0)
    own = [f for f in split_frames(data) if (f[4] if f[0] == V1_STX else f[6]) == 1]
    rate = sum(len(f) for f in own) / 10.0
    assert rate == pytest.approx(FIXTURE_BYTES_PER_S[profile], rel=0.15)
