"""A synchronous MCAP writer: JSON messages with JSON Schemas, one channel per topic.

The recorder drives it from its background thread; recovery and tlog import use it directly.
Chunks are zstd-compressed; `flush()` ends the open chunk and hands it to the OS, which is what
makes a killed process lose only what came after the last flush.
"""

from __future__ import annotations

import json
import struct
from collections.abc import Mapping
from pathlib import Path
from typing import IO, Any

from mcap.records import MessageIndex
from mcap.well_known import MessageEncoding, SchemaEncoding
from mcap.writer import CompressionType, Writer

from logs.encoding import encode_json
from logs.errors import RecordingError
from logs.foxglove import time_dict

PROFILE = ""
LIBRARY = "quadgcs-logs"
CHUNK_SIZE_BYTES = 512 * 1024


# a Message record's head: opcode 0x05, record length, channel, sequence, log and publish times
_MESSAGE_HEAD = struct.Struct("<BQHIQQ")
_MESSAGE_HEAD_FIELDS = 22
_INDEX_HEAD = struct.Struct("<BQHI")  # opcode 0x07, record length, channel, records' bytes


class _PackedIndex(MessageIndex):
    """A chunk's message index for one channel, written as the library writes it, in one
    piece instead of two calls per message."""

    def write(self, stream: Any) -> None:
        n = len(self.records)
        stream.write(_INDEX_HEAD.pack(7, 6 + 16 * n, self.channel_id, 16 * n))
        if n:
            stream.write(struct.pack(f"<{2 * n}Q", *(v for r in self.records for v in r)))


class LeanWriter(Writer):
    """mcap's `Writer`, writing a chunked message's record in one piece.

    The library builds a Message object per message and writes it field by field; a recording
    writes tens of thousands a minute. This does what its `add_message` does to the statistics,
    the chunk and its message index, with one struct, and leaves everything else (chunks,
    compression, indexes, summary) to the library: a test checks the files are byte for byte
    the library's own. A library whose internals are not the ones this was written against gets
    its own `add_message`."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self._chunk = getattr(self, "_Writer__chunk_builder", None)
        self._stats = getattr(self, "_Writer__statistics", None)
        self._chunk_size = getattr(self, "_Writer__chunk_size", None)
        self._finalize = getattr(self, "_Writer__maybe_finalize_chunk", None)
        self._lean = None not in (self._chunk, self._stats, self._chunk_size, self._finalize) \
            and all(hasattr(self._chunk, a) for a in ("record_writer", "message_indices",
                                                      "num_messages", "message_start_time"))

    def add_message(self, channel_id: int, log_time: int, data: bytes, publish_time: int,
                    sequence: int = 0) -> None:
        """As `Writer.add_message`."""
        if not self._lean:
            super().add_message(channel_id, log_time, data, publish_time, sequence)
            return
        st, cb = self._stats, self._chunk
        assert st is not None and cb is not None and self._finalize is not None
        if st.message_count == 0 or log_time < st.message_start_time:
            st.message_start_time = log_time
        if log_time > st.message_end_time:
            st.message_end_time = log_time
        st.channel_message_counts[channel_id] += 1
        st.message_count += 1
        if cb.num_messages == 0 or log_time < cb.message_start_time:
            cb.message_start_time = log_time
        if log_time > cb.message_end_time:
            cb.message_end_time = log_time
        index = cb.message_indices.get(channel_id)
        if index is None:
            index = cb.message_indices[channel_id] = _PackedIndex(channel_id=channel_id,
                                                                   records=[])
        records = cb.record_writer
        index.records.append((log_time, records.count))
        cb.num_messages += 1
        records.write(_MESSAGE_HEAD.pack(5, _MESSAGE_HEAD_FIELDS + len(data), channel_id,
                                         sequence, log_time, publish_time))
        records.write(data)
        if records.count > self._chunk_size:
            self._finalize()


def schema_name_for_topic(topic: str) -> str:
    """A schema name for a dict payload that brought none: derived from the topic."""
    return "quadgcs" + topic.replace("/", ".")


class McapSink:
    """Write JSON messages to an MCAP file; schemas and channels register on first use."""

    def __init__(self, path: Path, *, chunk_size: int = CHUNK_SIZE_BYTES) -> None:
        self.path = Path(path)
        try:
            self._file: IO[bytes] = open(self.path, "wb")  # noqa: SIM115 (closed in close())
        except OSError as exc:
            raise RecordingError(f"{self.path}: cannot write: {exc.strerror or exc}") from exc
        self._writer = LeanWriter(
            self._file, chunk_size=chunk_size, compression=CompressionType.ZSTD
        )
        self._writer.start(profile=PROFILE, library=LIBRARY)
        self._channels: dict[str, int] = {}
        self._schemas: dict[tuple[str, str], int] = {}
        self._sequence: dict[int, int] = {}
        self._closed = False

    def has_topic(self, topic: str) -> bool:
        """True once a channel exists for `topic`."""
        return topic in self._channels

    def add_topic(self, topic: str, schema_name: str, schema: Mapping[str, Any]) -> int:
        """Register `topic` with a JSON Schema (reused when name and text match)."""
        text = json.dumps(schema, separators=(",", ":"), sort_keys=True)
        key = (schema_name, text)
        schema_id = self._schemas.get(key)
        if schema_id is None:
            schema_id = self._writer.register_schema(
                name=schema_name, encoding=SchemaEncoding.JSONSchema, data=text.encode()
            )
            self._schemas[key] = schema_id
        channel_id = self._writer.register_channel(
            topic=topic, message_encoding=MessageEncoding.JSON, schema_id=schema_id
        )
        self._channels[topic] = channel_id
        self._sequence[channel_id] = 0
        return channel_id

    def write(
        self, topic: str, log_time_ns: int, message: Mapping[str, Any], *, stamp: bool = False
    ) -> None:
        """Write one JSON message on a registered topic; `stamp` fills `timestamp` from log time."""
        if stamp and "timestamp" not in message:
            message = {"timestamp": time_dict(log_time_ns), **message}
        self.write_bytes(topic, log_time_ns, encode_json(message))

    def write_bytes(self, topic: str, log_time_ns: int, data: bytes) -> None:
        """Write already-encoded JSON on a registered topic."""
        channel_id = self._channels[topic]
        seq = self._sequence[channel_id] + 1
        self._sequence[channel_id] = seq
        self._writer.add_message(
            channel_id=channel_id,
            log_time=log_time_ns,
            publish_time=log_time_ns,
            data=data,
            sequence=seq,
        )

    def write_metadata(self, name: str, data: Mapping[str, str]) -> None:
        """An MCAP Metadata record (string → string)."""
        self._writer.add_metadata(name, {str(k): str(v) for k, v in data.items()})
        self._file.flush()

    def flush(self) -> None:
        """End the open chunk and push everything written so far to the OS."""
        self._writer.flush()  # type: ignore[no-untyped-call]  # mcap leaves it unannotated

    def close(self) -> None:
        """Write the summary and index, then close the file."""
        if self._closed:
            return
        self._closed = True
        try:
            self._writer.finish()  # type: ignore[no-untyped-call]  # mcap leaves it unannotated
        finally:
            self._file.close()
