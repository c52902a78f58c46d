"""The SITL's own frame packer sends exactly the bytes pymavlink would pack."""

from __future__ import annotations

import pytest
from pymavlink.dialects.v20 import ardupilotmega as mavlink

from sitl.link.codec import MavCodec
from sitl.link.packer import FramePacker
from sitl.lockstep import PORT_BACKLOG_BYTES, MemoryPort, start


def _open(port: MemoryPort) -> MemoryPort:
    """The port with a client on it, as the station's link opening it does."""
    port.connect()
    return port


def _streamed(profile: str) -> list[mavlink.MAVLink_message]:
    sitl = start(profile, seed=2)
    port, mocap, truth = (_open(p) for p in (sitl.vehicle_port(1), sitl.mocap_port(),
                                             sitl.truth_port()))
    gcs = mavlink.MAVLink(None, srcSystem=255, srcComponent=190)
    v1 = profile == "apm25"
    for msg in (mavlink.MAVLink_heartbeat_message(6, 8, 0, 0, 4, 3),
                mavlink.MAVLink_request_data_stream_message(1, 1, 0, 40, 1),
                mavlink.MAVLink_param_request_list_message(1, 1)):
        port.write(msg.pack(gcs, force_mavlink1=v1))
    data = bytearray()
    for k in range(1, 301):
        sitl.advance_to(k * 0.01)
        for p in (port, mocap, truth):
            data += p.read(PORT_BACKLOG_BYTES)
    parser = mavlink.MAVLink(None)
    parser.robust_parsing = True
    return [m for m in parser.parse_buffer(bytes(data)) or [] if m.get_type() != "BAD_DATA"]


@pytest.mark.skipif(not FramePacker.available(),
                    reason="fastcrc (the packer's CRC) is not installed: the SITL packs "
                    "with pymavlink")
@pytest.mark.parametrize("profile", ["apm25", "copter4"])
def test_every_frame_is_what_pymavlink_packs(profile: str) -> None:
    msgs = _streamed(profile)
    kinds = {m.get_type() for m in msgs}
    # the whole telemetry set, the companion's, motion capture, truth and parameters
    assert {"ATTITUDE", "HEARTBEAT", "SYS_STATUS", "DISTANCE_SENSOR", "ATT_POS_MOCAP",
            "LOCAL_POSITION_NED", "PARAM_VALUE", "STATUSTEXT"} <= kinds, kinds
    assert len(kinds) >= 15
    for m in msgs:
        h = m.get_header()
        wire = bytes(m.get_msgbuf())  # before packing again: pymavlink keeps its last packing
        ref = MavCodec(h.srcSystem, h.srcComponent, mavlink1_only=profile == "apm25")
        ref._packer = None  # pymavlink's own packing
        ref.mav.seq = h.seq
        assert ref.encode(m) == wire, m.get_type()


def test_messages_made_without_the_constructor_hold_what_it_stores() -> None:
    # every message class the dialect has: those made from a copy must match attribute by
    # attribute, in order and type; the others are the constructor itself
    from sitl.link.codec import messages

    def view(m: mavlink.MAVLink_message) -> list[tuple[str, str, str]]:
        return [(k, type(v).__name__, repr(vars(v) if k == "_header" else v))
                for k, v in vars(m).items()]

    copied = 0
    for cls in mavlink.mavlink_map.values():
        name = cls.__name__
        make = getattr(messages, name)
        if make is cls:
            continue
        copied += 1
        n = len(cls.fieldnames)
        full = [(7 * i + 3) % 200 for i in range(n)]
        assert view(make(*full)) == view(cls(*full)), name
        required = n - len(cls.__init__.__defaults__ or ())  # extensions have defaults
        assert view(make(*full[:required])) == view(cls(*full[:required])), name
        assert make(*full) is not make(*full) and make(*full)._header is not make(*full)._header
    assert copied > 100
    with pytest.raises(TypeError):
        messages.MAVLink_attitude_message(1, 2.0)  # too few: the constructor's own error
