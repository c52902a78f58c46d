"""Turn a truncated recording (the station was killed) into a valid, indexed MCAP file.

Every whole record is read linearly — schemas, channels, metadata and the messages of every
complete chunk — and rewritten through a fresh writer, which adds the summary and indexes.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

from mcap.records import Channel, Message, Metadata, Schema
from mcap.writer import CompressionType, Writer

from logs.errors import RecordingError
from logs.mcap_sink import LIBRARY
from logs.reader import MCAP_MAGIC, read_whole_records


@dataclass(frozen=True, slots=True)
class RecoverResult:
    """What a recovery kept."""

    output: Path
    messages: int
    topics: int
    first_ns: int
    last_ns: int
    was_truncated: bool


def default_recovered_path(path: Path) -> Path:
    """`flight.mcap` → `flight.recovered.mcap` beside it."""
    return path.with_name(f"{path.stem}.recovered.mcap")


def recover(
    src: str | os.PathLike[str], dst: str | os.PathLike[str] | None = None
) -> RecoverResult:
    """Rewrite every whole record of `src` into a valid indexed MCAP at `dst`."""
    src_path = Path(src)
    dst_path = Path(dst) if dst is not None else default_recovered_path(src_path)
    if not src_path.is_file():
        raise RecordingError(f"{src_path}: no such file")
    with open(src_path, "rb") as stream:
        if stream.read(len(MCAP_MAGIC)) != MCAP_MAGIC:
            raise RecordingError(f"{src_path}: not an MCAP file (bad magic bytes)")
    if dst_path.exists() and dst_path.resolve() == src_path.resolve():
        raise RecordingError(f"{dst_path}: the output must not be the input file")
    records, clean = read_whole_records(src_path)
    try:
        out = open(dst_path, "wb")  # noqa: SIM115 (closed below, also on error)
    except OSError as exc:
        raise RecordingError(f"{dst_path}: cannot write: {exc.strerror or exc}") from exc
    schema_ids: dict[int, int] = {}
    channel_ids: dict[int, int] = {}
    count = 0
    first_ns = last_ns = 0
    try:
        writer = Writer(out, compression=CompressionType.ZSTD)
        writer.start(library=LIBRARY)
        for record in records:
            if isinstance(record, Schema):
                schema_ids[record.id] = writer.register_schema(
                    name=record.name, encoding=record.encoding, data=record.data
                )
            elif isinstance(record, Channel):
                channel_ids[record.id] = writer.register_channel(
                    topic=record.topic,
                    message_encoding=record.message_encoding,
                    schema_id=schema_ids.get(record.schema_id, 0),
                    metadata=dict(record.metadata),
                )
            elif isinstance(record, Metadata):
                writer.add_metadata(record.name, dict(record.metadata))
            elif isinstance(record, Message) and record.channel_id in channel_ids:
                writer.add_message(
                    channel_id=channel_ids[record.channel_id],
                    log_time=record.log_time,
                    publish_time=record.publish_time,
                    data=record.data,
                    sequence=record.sequence,
                )
                first_ns = record.log_time if count == 0 else min(first_ns, record.log_time)
                last_ns = max(last_ns, record.log_time)
                count += 1
        writer.finish()  # type: ignore[no-untyped-call]  # mcap leaves it unannotated
    except OSError as exc:
        raise RecordingError(f"{dst_path}: cannot write: {exc.strerror or exc}") from exc
    finally:
        out.close()
    return RecoverResult(
        output=dst_path,
        messages=count,
        topics=len(channel_ids),
        first_ns=first_ns,
        last_ns=last_ns,
        was_truncated=not clean,
    )
