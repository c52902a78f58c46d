"""A recording (or a tlog, through its import) read into `logs.check.FlightSeries`.

`logs/` may not decode MAVLink, so the raw frames (`/mavlink/rx`, `/mavlink/tx`) are decoded
here with the link's own parser (`firmware_link`). A recording that has the station's topics is
read from them; one without (an imported tlog from any ground station) gets its vehicle records
from the same converter the live link uses, on the same topics.
"""

from __future__ import annotations

import base64
import tempfile
from pathlib import Path
from typing import Any

from firmware_link.convert import RecordConverter
from firmware_link.frame_reader import FrameReader
from firmware_link.frames import make_parser
from gcs import topics
from logs import Recording, RecordingError, open_recording, to_jsonable
from logs.check import TOPICS, FlightSeries, FrameInfo
from logs.tlog import import_tlog

RAW_TOPICS = ("/mavlink/rx", "/mavlink/tx")
_KEPT_FIELDS = {
    "SET_MODE": ("custom_mode",),
    "COMMAND_LONG": ("command", "param1", "param2"),
    "REQUEST_DATA_STREAM": ("req_stream_id", "req_message_rate", "start_stop"),
    "RC_CHANNELS_OVERRIDE": ("chan3_raw",),
}


_V1, _V2 = 0xFE, 0xFD
# what a tlog's vehicle frames must be decoded for (the rest count only by their header)
_DECODED_RX = frozenset({"HEARTBEAT", "RAW_IMU", "VFR_HUD", "SYS_STATUS", "STATUSTEXT",
                         "COMMAND_ACK", "SIMSTATE", "SIM_STATE", "ATT_POS_MOCAP"})


def _mavlink_map() -> dict[int, Any]:
    from pymavlink.dialects.v20 import ardupilotmega as mavlink

    return dict(mavlink.mavlink_map)


def _message_name(msg_id: float) -> str:
    cls = _mavlink_map().get(int(msg_id))
    return str(cls.msgname) if cls is not None else str(int(msg_id))


def _header(data: bytes, names: dict[int, Any]) -> tuple[int, int, int, str] | None:
    """(seq, sysid, compid, message name) from a frame's header, None for no frame."""
    if len(data) >= 8 and data[0] == _V1:
        seq, sysid, compid, msg_id = data[2], data[3], data[4], data[5]
    elif len(data) >= 12 and data[0] == _V2:
        seq, sysid, compid = data[4], data[5], data[6]
        msg_id = data[7] | (data[8] << 8) | (data[9] << 16)
    else:
        return None
    cls = names.get(msg_id)
    return seq, sysid, compid, str(cls.msgname) if cls is not None else str(msg_id)


def gather(recording: Recording) -> FlightSeries:
    """Read the recording once into the checks' series."""
    fs = FlightSeries()
    start_ns = recording.start_ns
    have = set(recording.counts)
    station = any(t.startswith("/vehicle/") or t.startswith("/gcs/") for t in have)
    wanted = sorted((TOPICS & have) | (set(RAW_TOPICS) & have))
    readers = {d: FrameReader(make_parser(255, 190)) for d in ("rx", "tx")}
    converter = RecordConverter()
    names = _mavlink_map()
    for topic, log_ns, message in recording.messages(wanted):
        t_s = (log_ns - start_ns) / 1e9
        if topic not in RAW_TOPICS:
            fs.message(topic, t_s, message)
            continue
        direction = topic.rsplit("/", 1)[1]
        try:
            data = base64.b64decode(message["data"], validate=True)
        except (KeyError, TypeError, ValueError):
            continue  # a frame without its bytes is dropped, as a bad byte on a link
        head = _header(data, names)
        if head is None:
            continue
        seq, sysid, compid, kind = head
        if direction == "rx" and (station or kind not in _DECODED_RX):
            fs.frame(FrameInfo(t_s, direction, sysid, compid, seq, kind))
            continue
        for msg in readers[direction].parse(data):
            _take(fs, msg, direction, t_s, converter if not station else None)
    return fs


def _take(fs: FlightSeries, msg: Any, direction: str, t_s: float,
          converter: RecordConverter | None) -> None:
    kind = msg.get_type()
    if kind == "BAD_DATA":
        return
    fields: dict[str, Any] = {}
    for name in _KEPT_FIELDS.get(kind, ()):
        fields[name] = getattr(msg, name, None)
    if kind == "COMMAND_LONG" and fields.get("command") == 511:
        fields["param1"] = _message_name(fields["param1"])
    fs.frame(FrameInfo(t_s, direction, msg.get_srcSystem(), msg.get_srcComponent(),
                       msg.get_seq(), kind, fields))
    if converter is None or direction != "rx":
        return
    for record in converter.convert(msg, t_s):
        topic = topics.topic_for(record)
        if topic is not None:
            fs.message(topic, t_s, to_jsonable(record))


def gather_file(path: Path) -> FlightSeries:
    """An MCAP recording, or a tlog (by its `.tlog` suffix) imported to a temporary MCAP first."""
    if path.suffix.lower() != ".tlog":
        return gather(open_recording(path, allow_truncated=True))
    if not path.exists():
        raise RecordingError(f"{path}: no such file")
    with tempfile.TemporaryDirectory(prefix="quadgcs-check-") as tmp:
        out = Path(tmp) / (path.stem + ".mcap")
        import_tlog(path, out)
        return gather(open_recording(out))
