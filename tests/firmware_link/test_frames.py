"""Frame parsing: garbage and bad CRCs counted not raised, sequence gaps, raw tap, signing."""

from __future__ import annotations

import pytest

from firmware_link import dialect_of_frame
from firmware_link.frames import FrameEndpoint
from firmware_link.protocol import WireVersion, mavlink
from firmware_link.records import Dialect
from worldfile import SigningKeyError, key_from_passphrase, load_signing_key


class Clock:
    """A simulated clock."""

    def __init__(self) -> None:
        self.t = 100.0

    def __call__(self) -> float:
        return self.t


def frames_from(sender, count: int, start_seq: int = 0) -> list[bytes]:
    out = []
    for k in range(count):
        msg = sender.attitude_encode(k, 0.1, 0.2, 0.3, 0, 0, 0)
        sender.seq = (start_seq + k) % 256
        out.append(bytes(msg.pack(sender)))
    return out


def make_endpoint(tap=None) -> FrameEndpoint:
    return FrameEndpoint(None, source_system=255, source_component=190, clock=Clock(), on_raw=tap)


def test_good_frames_are_tapped_byte_exact_and_counted() -> None:
    tapped = []
    ep = make_endpoint(lambda d, t, b: tapped.append((d, t, b)))
    frames = frames_from(mavlink.MAVLink(None, 1, 1), 5)
    msgs = ep.feed(b"".join(frames))
    assert [m.get_type() for m in msgs] == ["ATTITUDE"] * 5
    assert [b for _, _, b in tapped] == frames
    assert {d for d, _, _ in tapped} == {"rx"} and tapped[0][1] == 100.0
    stats = ep.tally.snapshot(100.0)
    assert stats.rx_messages == 5 and stats.rx_bytes == sum(map(len, frames))
    assert stats.garbage_bytes == 0 and stats.lost_messages == 0


def test_garbage_and_bad_crc_are_counted_and_dropped() -> None:
    ep = make_endpoint()
    good = frames_from(mavlink.MAVLink(None, 1, 1), 3)
    corrupt = bytearray(good[1])
    corrupt[12] ^= 0xFF  # flip payload bits: CRC no longer matches
    junk = bytes(range(1, 40))  # no 0xFD/0xFE in it
    msgs = ep.feed(junk + good[0] + bytes(corrupt) + good[2])
    assert len(msgs) == 2
    stats = ep.tally.snapshot(100.0)
    assert stats.bad_frames == 1
    assert stats.garbage_bytes == len(junk) + len(corrupt)


def test_sequence_gaps_count_lost_messages_per_sender() -> None:
    ep = make_endpoint()
    sender = mavlink.MAVLink(None, 1, 1)
    frames = frames_from(sender, 10, start_seq=250)  # wraps through 255 → 0
    kept = frames[:3] + frames[6:]  # three lost
    ep.feed(b"".join(kept))
    other = frames_from(mavlink.MAVLink(None, 1, 158), 2, start_seq=7)
    ep.feed(b"".join(other))
    assert ep.tally.snapshot(100.0).lost_messages == 3


def test_mavlink1_vehicle_gets_8_channel_overrides_and_v1_frames() -> None:
    ep = make_endpoint()
    ep.wire = WireVersion.V1
    msg = ep.encoder.rc_channels_override_encode(1, 1, 1500, 1500, 1200, 1500, *[65535] * 4)
    frame = bytes(msg.pack(ep.encoder))
    assert frame[0] == 0xFE and frame[1] == 18  # 8 channels + 2 target bytes
    assert dialect_of_frame(frame) is Dialect.APM25
    ep.wire = WireVersion.V2
    v2 = bytes(ep.encoder.heartbeat_encode(6, 8, 0, 0, 4).pack(ep.encoder))
    assert dialect_of_frame(v2) is Dialect.COPTER4
    assert dialect_of_frame(b"") is Dialect.UNKNOWN


def test_signing_refuses_unsigned_and_wrongly_signed_frames() -> None:
    key = key_from_passphrase("indoor flight")
    ep = make_endpoint()
    ep.set_signing(key, link_id=0, timestamp=1_000_000)
    vehicle = mavlink.MAVLink(None, 1, 1)
    vehicle.signing.secret_key = key
    vehicle.signing.sign_outgoing = True
    vehicle.signing.timestamp = 1_000_500
    stranger = mavlink.MAVLink(None, 1, 1)
    impostor = mavlink.MAVLink(None, 1, 1)
    impostor.signing.secret_key = bytes(32)
    impostor.signing.sign_outgoing = True
    impostor.signing.timestamp = 1_000_600
    good = frames_from(vehicle, 2)
    msgs = ep.feed(good[0] + frames_from(stranger, 1)[0] + frames_from(impostor, 1)[0] + good[1])
    assert len(msgs) == 2
    assert ep.tally.snapshot(100.0).signature_refusals == 2
    ep.wire = WireVersion.V2
    out = bytes(ep.encoder.heartbeat_encode(6, 8, 0, 0, 4).pack(ep.encoder))
    assert out[0] == 0xFD and out[2] & 0x01  # incompat flag: signed
    assert len(out) == 12 + 9 + 13


def test_key_files_raw_or_passphrase(tmp_path) -> None:
    raw = tmp_path / "raw.key"
    raw.write_bytes(bytes(range(32)))
    assert load_signing_key(raw) == bytes(range(32))
    phrase = tmp_path / "phrase.key"
    phrase.write_text("indoor flight\n")
    assert load_signing_key(phrase) == key_from_passphrase("indoor flight")
    assert len(key_from_passphrase("x")) == 32
    binary = tmp_path / "bad.key"
    binary.write_bytes(b"\xff\xfe" * 5)
    with pytest.raises(SigningKeyError, match="expected 32 raw bytes"):
        load_signing_key(binary)
    with pytest.raises(SigningKeyError, match="cannot read"):
        load_signing_key(tmp_path / "missing.key")
