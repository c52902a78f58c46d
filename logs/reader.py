"""Open a recorded flight: topics, counts, metadata, and its messages as dicts in time order.

An indexed (properly closed) file is read through its summary. A truncated one — the station
was killed before `close()` — fails the indexed reader; `open_recording(..., allow_truncated=True)`
then reads every whole chunk linearly (mcap's non-seeking reader, in file order) and sorts.
"""

from __future__ import annotations

import json
import os
from collections.abc import Iterable, Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from mcap.exceptions import McapError
from mcap.reader import SeekingReader
from mcap.records import Channel, Message, Metadata, Schema
from mcap.stream_reader import StreamReader

from logs.errors import RecordingError
from logs.flight_file import METADATA_NAME

MCAP_MAGIC = b"\x89MCAP0\r\n"
TRUNCATED_HINT = "truncated: recover it with quadgcs logs recover"


@dataclass(frozen=True, slots=True)
class TopicInfo:
    """One topic of a recording: its schema and how many messages it holds."""

    topic: str
    schema_name: str
    message_encoding: str
    count: int


def decode_metadata(records: Iterable[tuple[str, Mapping[str, str]]]) -> dict[str, Any]:
    """Merge the flight metadata records, turning the JSON-encoded values back into values."""
    merged: dict[str, Any] = {}
    for name, data in records:
        if name != METADATA_NAME:
            continue
        json_keys = set(json.loads(data.get("json_keys", "[]")))
        for key, value in data.items():
            if key == "json_keys":
                continue
            merged[key] = json.loads(value) if key in json_keys else value
    return merged


def read_whole_records(path: Path) -> tuple[list[Any], bool]:
    """Every whole record of a possibly truncated file, and whether it ended cleanly."""
    records: list[Any] = []
    with open(path, "rb") as stream:
        reader = StreamReader(stream, validate_crcs=True, record_size_limit=1 << 30)
        try:
            for record in reader.records:
                records.append(record)
        except Exception:
            # A torn record at the end fails in many ways (short read, zstd frame, CRC, struct);
            # whichever it is, the whole records before it are the recording.
            return records, False
    return records, True


class Recording:
    """A flight recording opened for reading (see `open_recording`)."""

    def __init__(self, path: Path, *, truncated: bool) -> None:
        self.path = path
        self.truncated = truncated
        self._channels: dict[int, Channel] = {}
        self._schemas: dict[int, Schema] = {}
        self._counts: dict[str, int] = {}
        self._metadata_records: list[tuple[str, dict[str, str]]] = []
        self._start_ns = 0
        self._end_ns = 0
        self._linear: list[tuple[int, int, int, bytes]] | None = None
        if truncated:
            self._load_linear()
        else:
            self._load_summary()

    def _load_summary(self) -> None:
        with open(self.path, "rb") as stream:
            try:
                reader = SeekingReader(stream)
                summary = reader.get_summary()
                metadata = [(m.name, dict(m.metadata)) for m in reader.iter_metadata()]
            except (McapError, ValueError, EOFError, KeyError) as exc:
                raise RecordingError(f"{self.path}: corrupt MCAP summary ({exc})") from exc
        if summary is None:
            self._load_linear()
            return
        self._channels = dict(summary.channels)
        self._schemas = dict(summary.schemas)
        self._metadata_records = metadata
        stats = summary.statistics
        if stats is None:
            self._load_linear()
            return
        for channel_id, n in stats.channel_message_counts.items():
            topic = self._channels[channel_id].topic
            self._counts[topic] = self._counts.get(topic, 0) + n
        for channel in self._channels.values():
            self._counts.setdefault(channel.topic, 0)
        self._start_ns = stats.message_start_time
        self._end_ns = stats.message_end_time

    def _load_linear(self) -> None:
        records, _clean = read_whole_records(self.path)
        messages: list[tuple[int, int, int, bytes]] = []
        for record in records:
            if isinstance(record, Schema):
                self._schemas[record.id] = record
            elif isinstance(record, Channel):
                self._channels[record.id] = record
                self._counts.setdefault(record.topic, 0)
            elif isinstance(record, Message) and record.channel_id in self._channels:
                messages.append((record.log_time, len(messages), record.channel_id, record.data))
                topic = self._channels[record.channel_id].topic
                self._counts[topic] = self._counts.get(topic, 0) + 1
            elif isinstance(record, Metadata):
                self._metadata_records.append((record.name, dict(record.metadata)))
        messages.sort()
        self._linear = messages
        if messages:
            self._start_ns = messages[0][0]
            self._end_ns = messages[-1][0]

    @property
    def topics(self) -> list[str]:
        """Topic names, sorted."""
        return sorted(self._counts)

    @property
    def counts(self) -> dict[str, int]:
        """Messages per topic."""
        return dict(sorted(self._counts.items()))

    @property
    def topic_info(self) -> dict[str, TopicInfo]:
        """Schema name, encoding and count per topic."""
        out: dict[str, TopicInfo] = {}
        for channel in self._channels.values():
            schema = self._schemas.get(channel.schema_id)
            out[channel.topic] = TopicInfo(
                topic=channel.topic,
                schema_name=schema.name if schema else "",
                message_encoding=channel.message_encoding,
                count=self._counts.get(channel.topic, 0),
            )
        return dict(sorted(out.items()))

    def schema(self, topic: str) -> tuple[str, bytes]:
        """A topic's schema name and text as recorded (("", b"") for a schemaless topic)."""
        for channel in self._channels.values():
            if channel.topic == topic:
                schema = self._schemas.get(channel.schema_id)
                return (schema.name, bytes(schema.data)) if schema else ("", b"")
        raise RecordingError(f"{self.path}: no topic {topic!r}")

    @property
    def metadata(self) -> dict[str, Any]:
        """The flight's metadata (vehicle, software version, parameters, world/mission text…)."""
        return decode_metadata(self._metadata_records)

    @property
    def start_ns(self) -> int:
        """Log time of the first message, ns (UTC)."""
        return self._start_ns

    @property
    def end_ns(self) -> int:
        """Log time of the last message, ns (UTC)."""
        return self._end_ns

    @property
    def duration_s(self) -> float:
        """Seconds from the first message to the last."""
        return (self._end_ns - self._start_ns) / 1e9

    def _check_topics(self, topics: Iterable[str] | None) -> list[str] | None:
        if topics is None:
            return None
        wanted = [topics] if isinstance(topics, str) else list(topics)
        missing = [t for t in wanted if t not in self._counts]
        if missing:
            have = ", ".join(self.topics) or "none"
            raise RecordingError(f"{self.path}: no topic {', '.join(missing)} (topics: {have})")
        for topic in wanted:
            self._check_json(topic)
        return wanted

    def _check_json(self, topic: str) -> None:
        for channel in self._channels.values():
            if channel.topic == topic and channel.message_encoding != "json":
                raise RecordingError(
                    f"{self.path}: topic {topic} is encoded as "
                    f"{channel.message_encoding!r}, expected JSON"
                )

    def raw_messages(self, topics: Iterable[str] | None = None) -> Iterator[tuple[str, int, bytes]]:
        """(topic, log_time_ns, undecoded bytes) in log-time order."""
        wanted = self._check_topics(topics)
        if self._linear is not None:
            wanted_set = set(wanted) if wanted is not None else None
            for log_ns, _i, channel_id, data in self._linear:
                topic = self._channels[channel_id].topic
                if wanted_set is None or topic in wanted_set:
                    yield topic, log_ns, data
            return
        with open(self.path, "rb") as stream:
            reader = SeekingReader(stream)
            try:
                for _schema, channel, message in reader.iter_messages(
                    topics=wanted, log_time_order=True
                ):
                    yield channel.topic, message.log_time, message.data
            except (McapError, ValueError, EOFError) as exc:
                raise RecordingError(f"{self.path}: corrupt chunk ({exc})") from exc

    def messages(
        self, topics: Iterable[str] | None = None
    ) -> Iterator[tuple[str, int, dict[str, Any]]]:
        """(topic, log_time_ns, message dict) in log-time order; JSON topics only."""
        if topics is None:
            for channel in self._channels.values():
                self._check_json(channel.topic)
        for topic, log_ns, data in self.raw_messages(topics):
            try:
                message = json.loads(data)
            except (UnicodeDecodeError, json.JSONDecodeError) as exc:
                raise RecordingError(
                    f"{self.path}: message on {topic} at {log_ns} ns is not valid JSON"
                ) from exc
            yield topic, log_ns, message


def open_recording(path: str | os.PathLike[str], *, allow_truncated: bool = False) -> Recording:
    """Open an MCAP recording; a truncated file raises unless `allow_truncated`."""
    p = Path(path)
    if not p.exists():
        raise RecordingError(f"{p}: no such file")
    if p.is_dir():
        raise RecordingError(f"{p}: is a directory, expected an .mcap file")
    try:
        size = p.stat().st_size
        with open(p, "rb") as stream:
            head = stream.read(len(MCAP_MAGIC))
            tail = b""
            if size >= 2 * len(MCAP_MAGIC):
                stream.seek(size - len(MCAP_MAGIC))
                tail = stream.read(len(MCAP_MAGIC))
    except OSError as exc:
        raise RecordingError(f"{p}: cannot read: {exc.strerror or exc}") from exc
    if head != MCAP_MAGIC:
        raise RecordingError(f"{p}: not an MCAP file (bad magic bytes)")
    truncated = tail != MCAP_MAGIC
    if truncated and not allow_truncated:
        raise RecordingError(f"{p}: {TRUNCATED_HINT} {p}")
    return Recording(p, truncated=truncated)
