"""`FrameReader` makes of any byte stream the messages pymavlink's `parse_buffer` makes of it."""

from __future__ import annotations

import random
from typing import Any

import pytest

from firmware_link.frame_reader import FrameReader
from firmware_link.frames import make_parser
from firmware_link.protocol import mavlink, mavlink1
from sitl import lockstep


class _Sink:
    def __init__(self) -> None:
        self.data = bytearray()

    def write(self, data: bytes) -> None:
        self.data += data


def _sitl_bytes(profile: str, seconds: float) -> bytes:
    """What a vehicle, a motion-capture and a truth port send in `seconds` (interleaved)."""
    sim = lockstep.start(profile, seed=2)
    ports = [sim.vehicle_port(1), sim.mocap_port(), sim.truth_port()]
    for p in ports:
        p.connect()
    ask = _Sink()
    mavlink1.MAVLink(ask, 255, 190).request_data_stream_send(1, 1, 0, 40, 1)  # every stream
    ports[0].write(bytes(ask.data))
    out = bytearray()
    while sim.t_s < seconds:
        sim.advance_to(sim.t_s + 0.05)
        for p in ports:
            out += p.read(1 << 20)
    return bytes(out)


def _odd_frames() -> bytes:
    """Strings, arrays, trailing zeros, MAVLink 1 and 2, a signed frame: what streams lack."""
    out = _Sink()
    v2 = mavlink.MAVLink(out, 1, 1)
    v1 = mavlink1.MAVLink(out, 1, 1)
    for mav in (v1, v2):
        mav.statustext_send(4, b"PreArm: hello")
        mav.param_value_send(b"RNG_MAX_CM", 700.0, 9, 300, 12)
        mav.rc_channels_override_send(1, 1, 1500, 1500, 1000, 1500, 0, 0, 0, 0)
        mav.heartbeat_send(2, 3, 81, 0, 3)
        mav.command_ack_send(511, 0)
        mav.servo_output_raw_send(1, 0, *([1100] * 8))
    signer = mavlink.MAVLink(out, 1, 1)
    signer.signing.secret_key = bytes(range(32))
    signer.signing.sign_outgoing = True
    signer.signing.link_id = 1
    signer.signing.timestamp = 10**9
    signer.heartbeat_send(2, 3, 81, 0, 3)
    return bytes(out.data)


def _view(m: Any) -> tuple[Any, ...]:
    """Everything a message holds: every attribute, its type and order, and its header's."""
    attrs = tuple((k, type(v).__name__, repr(vars(v) if k == "_header" else v))
                  for k, v in vars(m).items())
    return (type(m).__name__, m.get_type(), getattr(m, "reason", None), attrs)


def _both(chunks: list[bytes], key: bytes | None = None) -> tuple[list[Any], list[Any]]:
    ours_parser, theirs = make_parser(255, 190), make_parser(255, 190)
    for p in (ours_parser, theirs):
        p.signing.secret_key = key
    reader = FrameReader(ours_parser)
    ours: list[Any] = []
    ref: list[Any] = []
    for c in chunks:
        ours += [_view(m) for m in reader.parse(c)]
        ref += [_view(m) for m in theirs.parse_buffer(c) or ()]
    assert ours_parser.total_packets_received == theirs.total_packets_received
    assert ours_parser.total_receive_errors == theirs.total_receive_errors
    return ours, ref


def _cut(data: bytes, rng: random.Random) -> list[bytes]:
    chunks, i = [], 0
    while i < len(data):
        n = rng.choice((1, 2, 3, 7, 40, 300, 4096))
        chunks.append(data[i:i + n])
        i += n
    return chunks


@pytest.mark.parametrize("profile", ["apm25", "copter4"])
def test_clean_traffic_decodes_as_pymavlink_decodes_it(profile: str) -> None:
    data = _sitl_bytes(profile, 3.0) + _odd_frames()
    ours, ref = _both(_cut(data, random.Random(1)))
    assert len(ours) > 1000 and ours == ref
    assert len({v[1] for v in ours}) > 10
    assert not any(v[1] == "BAD_DATA" for v in ours)


@pytest.mark.parametrize("seed", range(6))
def test_corrupted_traffic_gives_the_same_messages_and_bad_data(seed: int) -> None:
    rng = random.Random(seed)
    data = bytearray(_sitl_bytes("copter4" if seed % 2 else "apm25", 1.0) + _odd_frames())
    for _ in range(60):  # flipped bytes, lost runs, inserted garbage (magic bytes included)
        i = rng.randrange(len(data))
        what = rng.random()
        if what < 0.4:
            data[i] ^= 1 << rng.randrange(8)
        elif what < 0.7:
            del data[i:i + rng.randrange(1, 30)]
        else:
            data[i:i] = bytes(rng.choice((0x00, 0xFE, 0xFD, 0x55)) for _ in range(rng.randrange(9)))
    ours, ref = _both(_cut(bytes(data), rng))
    assert ours == ref
    assert any(v[1] == "BAD_DATA" for v in ours)


def test_a_signing_link_leaves_every_frame_to_pymavlink() -> None:
    data = _odd_frames()
    ours, ref = _both(_cut(data, random.Random(3)), key=bytes(range(32)))
    assert ours == ref and ours
