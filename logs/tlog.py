"""MAVLink telemetry logs (.tlog): import raw frames into MCAP, export them back.

A tlog, as MAVProxy, Mission Planner and pymavlink write and read it, is a plain sequence of
[8-byte big-endian UTC microseconds][one raw MAVLink frame]. Frames are delimited here from their
own headers (MAVLink 1: 0xFE, 8 bytes around the payload; MAVLink 2: 0xFD, 12 bytes, plus a
13-byte signature when incompat flag 0x01 is set), so `logs/` needs no MAVLink library. Direction
on import: frames from system id 255 (the GCS, `SYSID_MYGCS`) are "tx", all others "rx".
"""

from __future__ import annotations

import base64
import os
import struct
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

from logs.errors import RecordingError
from logs.flight_file import (
    METADATA_NAME,
    RAW_FRAME_SCHEMA,
    RAW_FRAME_SCHEMA_NAME,
    encode_metadata,
)
from logs.mcap_sink import McapSink
from logs.reader import Recording
from logs.topics import MAVLINK_RX_TOPIC, MAVLINK_TX_TOPIC

MAVLINK1_STX = 0xFE
MAVLINK2_STX = 0xFD
GCS_SYSID = 255
_TS = struct.Struct(">Q")


@dataclass(frozen=True, slots=True)
class TlogFrame:
    """One frame of a tlog: UTC µs, the raw bytes, and the sender's system id."""

    t_us: int
    data: bytes
    sysid: int


def frame_length(buf: bytes | memoryview, start: int) -> int:
    """Length of the MAVLink frame at `start`, or 0 if the bytes there do not start one."""
    if start + 2 > len(buf):
        return 0
    stx = buf[start]
    payload_len = buf[start + 1]
    if stx == MAVLINK1_STX:
        return 8 + payload_len
    if stx == MAVLINK2_STX:
        if start + 3 > len(buf):
            return 0
        signed = buf[start + 2] & 0x01
        return 12 + payload_len + (13 if signed else 0)
    return 0


def frame_sysid(frame: bytes) -> int:
    """Sender system id from the frame header."""
    return frame[5] if frame[0] == MAVLINK2_STX else frame[3]


def read_tlog(path: str | os.PathLike[str]) -> Iterator[TlogFrame]:
    """Frames of a tlog in file order; a torn last frame is left out, garbage is an error."""
    p = Path(path)
    try:
        buf = p.read_bytes()
    except FileNotFoundError as exc:
        raise RecordingError(f"{p}: no such file") from exc
    except OSError as exc:
        raise RecordingError(f"{p}: cannot read: {exc.strerror or exc}") from exc
    pos = 0
    end = len(buf)
    while pos + 8 < end:
        (t_us,) = _TS.unpack_from(buf, pos)
        n = frame_length(buf, pos + 8)
        if n == 0:
            raise RecordingError(
                f"{p}: not a tlog: at byte {pos + 8} found 0x{buf[pos + 8]:02x}, "
                "expected a MAVLink frame start (0xFE or 0xFD) after an 8-byte timestamp"
            )
        if pos + 8 + n > end:
            return
        frame = bytes(buf[pos + 8 : pos + 8 + n])
        yield TlogFrame(t_us=t_us, data=frame, sysid=frame_sysid(frame))
        pos += 8 + n


@dataclass(frozen=True, slots=True)
class TlogImportResult:
    """Frames imported per direction."""

    output: Path
    rx: int
    tx: int


def import_tlog(
    tlog: str | os.PathLike[str], out: str | os.PathLike[str], *, vehicle: str = "vehicle1"
) -> TlogImportResult:
    """Copy a tlog's raw frames onto "/mavlink/rx" and "/mavlink/tx" of a new MCAP file."""
    tlog_path = Path(tlog)
    frames = read_tlog(tlog_path)
    first = next(frames, None)
    if first is None:
        raise RecordingError(f"{tlog_path}: no MAVLink frames in it")
    out_path = Path(out)
    sink = McapSink(out_path)
    counts = {MAVLINK_RX_TOPIC: 0, MAVLINK_TX_TOPIC: 0}
    try:
        sink.write_metadata(
            METADATA_NAME,
            encode_metadata({"vehicle": vehicle, "imported_from": tlog_path.name}),
        )
        for topic in counts:
            sink.add_topic(topic, RAW_FRAME_SCHEMA_NAME, RAW_FRAME_SCHEMA)
        frame: TlogFrame | None = first
        while frame is not None:
            topic = MAVLINK_TX_TOPIC if frame.sysid == GCS_SYSID else MAVLINK_RX_TOPIC
            message = {"data": base64.b64encode(frame.data).decode("ascii"), "len": len(frame.data)}
            sink.write(topic, frame.t_us * 1000, message)
            counts[topic] += 1
            frame = next(frames, None)
    finally:
        sink.close()
    return TlogImportResult(out_path, rx=counts[MAVLINK_RX_TOPIC], tx=counts[MAVLINK_TX_TOPIC])


def export_tlog(recording: Recording, out: str | os.PathLike[str]) -> int:
    """Write the recording's raw frames, both directions in log-time order, as a tlog."""
    topics = [t for t in (MAVLINK_RX_TOPIC, MAVLINK_TX_TOPIC) if t in recording.counts]
    if not topics:
        raise RecordingError(
            f"{recording.path}: no raw MAVLink frames (topics /mavlink/rx, /mavlink/tx) to export"
        )
    out_path = Path(out)
    n = 0
    try:
        with open(out_path, "wb") as f:
            for topic, log_ns, message in recording.messages(topics):
                try:
                    data = base64.b64decode(message["data"], validate=True)
                except (KeyError, TypeError, ValueError) as exc:
                    raise RecordingError(
                        f"{recording.path}: frame on {topic} at {log_ns} ns has no base64 data"
                    ) from exc
                f.write(_TS.pack((log_ns + 500) // 1000))
                f.write(data)
                n += 1
    except OSError as exc:
        raise RecordingError(f"{out_path}: cannot write: {exc.strerror or exc}") from exc
    return n
