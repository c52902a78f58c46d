"""What an MCAP flight file holds besides its records: its name and directory, its metadata
record, and the schema and topics of the raw MAVLink frames.
"""

from __future__ import annotations

import datetime as dt
import enum
import json
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from logs.encoding import to_jsonable
from logs.errors import RecordingError
from logs.topics import MAVLINK_RX_TOPIC, MAVLINK_TX_TOPIC

METADATA_NAME = "quadgcs.flight"
RAW_FRAME_SCHEMA_NAME = "quadgcs.MavlinkFrame"
RAW_FRAME_SCHEMA: dict[str, Any] = {
    "type": "object",
    "title": "MAVLink frame",
    "description": "One raw MAVLink frame as it crossed the link, base64",
    "properties": {
        "data": {"type": "string", "contentEncoding": "base64"},
        "len": {"type": "integer", "minimum": 0},
    },
}


class Direction(enum.Enum):
    """Which way a raw MAVLink frame crossed the link."""

    RX = "rx"
    TX = "tx"


RAW_TOPICS = {Direction.RX: MAVLINK_RX_TOPIC, Direction.TX: MAVLINK_TX_TOPIC}
# by member or value, without an Enum call on every frame
RAW_TOPIC_OF: dict[Direction | str, str] = {
    **{d: t for d, t in RAW_TOPICS.items()}, **{d.value: t for d, t in RAW_TOPICS.items()}}


def flight_file_name(started_utc: dt.datetime, vehicle: str) -> str:
    """`2026-11-22T10-31-05Z_vehicle1.mcap`: sortable, and safe on every file system."""
    safe_vehicle = "".join(c if c.isalnum() or c in "-_" else "_" for c in vehicle) or "vehicle"
    return f"{started_utc.strftime('%Y-%m-%dT%H-%M-%SZ')}_{safe_vehicle}.mcap"


def resolve_path(path_or_dir: str | Path, started_utc: dt.datetime, vehicle: str) -> Path:
    target = Path(path_or_dir)
    if target.suffix == ".mcap" and not target.is_dir():
        parent = target.parent
    else:
        parent = target
        target = target / flight_file_name(started_utc, vehicle)
        base = target.stem
        n = 1
        while target.exists():
            target = parent / f"{base}-{n}.mcap"
            n += 1
    try:
        parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise RecordingError(f"{parent}: cannot create directory: {exc.strerror or exc}") from exc
    return target


def software_version() -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("quadgcs")
    except PackageNotFoundError:
        return "unknown"


def encode_metadata(metadata: Mapping[str, Any]) -> dict[str, str]:
    """MCAP metadata is string → string: non-strings become JSON, listed under `json_keys`."""
    out: dict[str, str] = {}
    json_keys = []
    for key, value in metadata.items():
        if isinstance(value, str):
            out[str(key)] = value
        else:
            out[str(key)] = json.dumps(to_jsonable(value), separators=(",", ":"))
            json_keys.append(str(key))
    if json_keys:
        out["json_keys"] = json.dumps(json_keys)
    return out


def files_metadata(**paths: str | Path | None) -> dict[str, str]:
    """World/mission/config files for the metadata record: `world_path` and `world` (its text).

    A missing or unreadable file is noted in place of its text rather than stopping a flight.
    """
    out: dict[str, str] = {}
    for name, path in paths.items():
        if path is None:
            continue
        p = Path(path)
        out[f"{name}_path"] = str(p)
        try:
            out[name] = p.read_text(encoding="utf-8", errors="replace")
        except OSError as exc:
            out[name] = f"<unreadable: {exc.strerror or exc}>"
    return out
