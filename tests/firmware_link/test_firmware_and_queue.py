"""Firmware verdicts from evidence, and the send queue's rules (pure, no sockets)."""

from __future__ import annotations

from types import SimpleNamespace

from firmware_link.firmware import (
    FirmwareEvidence,
    decide_firmware,
    decode_sw_version,
    parse_banner,
)
from firmware_link.protocol import WireVersion
from firmware_link.records import Dialect
from firmware_link.tx_queue import TxQueue

V1_FRAME = b"\xfe\x09"
V2_FRAME = b"\xfd\x09"


def evidence(frame: bytes, params: set[str] = frozenset(), missing: set[str] = frozenset(),
             **kw: object) -> FirmwareEvidence:
    ev = FirmwareEvidence()
    ev.first_frame(frame, 2)
    ev.params_seen |= set(params)
    ev.params_missing |= set(missing)
    for key, value in kw.items():
        setattr(ev, key, value)
    return ev


def test_version_number_and_banner_decoding() -> None:
    assert decode_sw_version((4 << 24) | (7 << 16) | 0) == (4, 7, 0, "-dev")
    assert decode_sw_version((4 << 24) | (5 << 16) | (7 << 8) | 255) == (4, 5, 7, "")
    assert parse_banner("ArduCopter V3.2.1") == ("ArduCopter V3.2.1", (3, 2, 1))
    assert parse_banner("ArduCopter V4.7.0-dev (d2e4299f)") == ("ArduCopter V4.7.0-dev",
                                                                (4, 7, 0))
    assert parse_banner("APM:Copter V3.2.1") == ("ArduCopter V3.2.1", (3, 2, 1))
    assert parse_banner("Frame: QUAD") is None
    assert parse_banner("PreArm: INS not calibrated") is None


def test_autopilot_version_is_trusted_first() -> None:
    ev = evidence(V2_FRAME, {"MAV_GCS_SYSID", "MOT_THST_HOVER"})
    ev.autopilot_version(SimpleNamespace(flight_sw_version=(4 << 24) | (7 << 16),
                                         flight_custom_version=list(b"d2e4299f")))
    info = decide_firmware(ev)
    assert info.dialect is Dialect.COPTER4
    assert info.version == "ArduCopter V4.7.0-dev"
    assert info.gcs_sysid_param == "MAV_GCS_SYSID"
    assert info.version_number == (4, 7, 0)
    assert any("AUTOPILOT_VERSION" in e and "d2e4299f" in e for e in info.evidence)
    assert info.source == "AUTOPILOT_VERSION"
    assert info.label == "ArduCopter V4.7.0-dev (AUTOPILOT_VERSION)"


def test_a_321_is_told_by_its_parameters_and_banner() -> None:
    ev = evidence(V1_FRAME, {"SYSID_MYGCS", "THR_MID"}, {"MAV_GCS_SYSID", "MOT_THST_HOVER"},
                  version_refused=True)
    ev.statustext("ArduCopter V3.2.1")
    ev.statustext("Frame: QUAD")
    info = decide_firmware(ev)
    assert (info.dialect, info.version, info.gcs_sysid_param, info.wire) == (
        Dialect.APM25, "ArduCopter V3.2.1", "SYSID_MYGCS", WireVersion.V1)
    text = " | ".join(info.evidence)
    assert "THR_MID exists" in text and "not answered" in text and "'ArduCopter V3.2.1'" in text
    assert info.summary.startswith("ArduCopter V3.2.1: dialect APM25, MAVLink 1")
    assert info.source == "STATUSTEXT banner"
    assert info.summary.endswith("identified by STATUSTEXT banner")


def test_a_4x_on_a_mavlink1_port_is_not_an_apm25() -> None:
    info = decide_firmware(evidence(V1_FRAME, {"SYSID_MYGCS", "MOT_THST_HOVER"},
                                    version_refused=True))
    assert info.dialect is Dialect.COPTER4 and info.wire is WireVersion.V1
    assert info.version == "" and info.name == "ArduCopter 4.x"
    assert info.label == "ArduCopter 4.x (parameters: MOT_THST_HOVER)"
    assert any("not an APM 2.5" in e for e in info.evidence)


def test_the_wire_alone_is_only_a_hint() -> None:
    info = decide_firmware(evidence(V1_FRAME))
    assert info.dialect is Dialect.APM25
    assert any("only the wire version" in e and "hint" in e for e in info.evidence)
    assert any("assumed" in e for e in info.evidence)  # no GCS-id parameter was read
    assert info.label == "ArduCopter 3.x (heartbeat only: MAVLink 1 frames)"
    assert decide_firmware(evidence(V2_FRAME)).dialect is Dialect.COPTER4


def test_a_banner_decides_when_nothing_stronger_does() -> None:
    ev = evidence(V2_FRAME)
    ev.statustext("ArduCopter V4.7.0-dev (d2e4299f)")
    info = decide_firmware(ev)
    assert info.dialect is Dialect.COPTER4
    assert info.version == "ArduCopter V4.7.0-dev"
    assert info.gcs_sysid_param == "MAV_GCS_SYSID"  # from the version, not read: assumed


def test_override_slot_keeps_only_the_newest_and_goes_first() -> None:
    q = TxQueue(limit_bytes=100)
    assert q.put("hb", 30) and q.put("cmd", 30)
    q.put_override("rc1", 26)
    q.put_override("rc2", 26)
    assert q.override == "rc2" and q.replaced_overrides == 1
    assert not q.put("big", 50)  # 60 + 50 > 100: refused, counted
    assert q.overflows == 1 and q.queued_bytes == 86
    wire = bytearray()

    def write(view: memoryview) -> int:
        wire.extend(view)
        return len(view)

    q.flush(lambda m: m.encode() + b"|", write)
    assert wire == b"rc2|hb|cmd|" and q.idle and q.queued_bytes == 0


def test_a_partial_frame_is_finished_before_anything_else() -> None:
    q = TxQueue()
    room = [3]
    wire = bytearray()

    def write(view: memoryview) -> int:
        n = min(room[0], len(view))
        wire.extend(view[:n])
        room[0] -= n
        return n

    q.put("AAAA", 4)
    q.flush(lambda m: m.encode(), write)
    assert wire == b"AAA" and q.backpressure == 1 and q.queued_bytes == 1
    q.put_override("RR", 2)  # arrives while a frame is half out
    room[0] = 100
    q.flush(lambda m: m.encode(), write)
    assert wire == b"AAAARR" and q.idle
    q.put("B", 1)
    q.put_override("R", 1)
    assert q.clear() == 2 and q.idle
