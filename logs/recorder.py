"""Flight recorder: the station's loop thread queues records; a background thread writes MCAP.

`put`, `put_raw` and `event` only append to a queue (no disk, no JSON on the caller's thread), so
a 25 ms control tick pays well under a millisecond for recording. The writer thread converts
payloads, writes zstd chunks and flushes at least every `flush_interval_s`, so a process killed
with SIGKILL loses at most its last interval. A full queue drops and counts, never silently.

A simulated-time producer (`block_when_full`: a lockstep flight) has no tick deadline to protect
and must lose nothing: it writes its own queue, in batches and at least every interval, on its
own thread. A writer thread would only contend with it for the GIL, which cost a lockstep flight
more CPU than the writing itself.

Time: records carry the station's monotonic `t_s`; log times are nanoseconds on a UTC-anchored
timeline, `anchor_ns + t_s·1e9`, with `anchor_ns = wall clock − monotonic clock` taken once at
start, so the file's times read as UTC yet never jump when the wall clock is adjusted.
"""

from __future__ import annotations

import atexit
import base64
import dataclasses
import datetime as dt
import enum
import threading
import time
from collections import deque
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from types import TracebackType
from typing import Any

from logs.encoding import encode_json, schema_for_payload, to_jsonable
from logs.errors import RecordingError
from logs.flight_file import (
    METADATA_NAME,
    RAW_FRAME_SCHEMA,
    RAW_FRAME_SCHEMA_NAME,
    RAW_TOPIC_OF,
    Direction,
    encode_metadata,
    resolve_path,
    software_version,
)
from logs.foxglove import (
    FoxgloveMessage,
    LogLevel,
    foxglove_log,
    ned_display_transform,
    stamped,
)
from logs.foxglove_schemas import WELL_KNOWN_SCHEMAS, parse_log_level
from logs.mcap_sink import McapSink, schema_name_for_topic
from logs.topics import LOG_TOPIC, TF_TOPIC

DEFAULT_DIR = Path("flights")
YIELD_AFTER_S = 0.0002  # writer time slice before it lets other threads run
# A simulated-time producer writes its queue once this many records wait: few enough that they
# die young (4096 made the garbage collector's passes cost more than batching saved).
INLINE_BATCH = 512


Tap = Callable[[str, str, Mapping[str, Any], int, bytes], None]
"""(topic, schema name, JSON Schema, log time ns, the message's JSON) of each message written."""


class _Kind(enum.Enum):
    PUT = 1
    RAW = 2
    EVENT = 3
    METADATA = 4


@dataclass(frozen=True, slots=True)
class RecorderStats:
    """What the recorder did, per topic: written, dropped (queue full or closed), rejected."""

    written: dict[str, int]
    dropped: dict[str, int]
    rejected: dict[str, int]
    queued: int
    flushes: int
    error: str | None

    @property
    def total_written(self) -> int:
        """Messages written over all topics."""
        return sum(self.written.values())

    @property
    def total_dropped(self) -> int:
        """Messages dropped over all topics."""
        return sum(self.dropped.values())


class Recorder:
    """Record one flight to an MCAP file (see the module docstring)."""

    def __init__(
        self,
        path_or_dir: str | Path = DEFAULT_DIR,
        *,
        metadata: Mapping[str, Any],
        vehicle: str = "vehicle1",
        flush_interval_s: float = 1.0,
        max_queue: int = 100_000,
        anchor_ns: int | None = None,
        block_when_full: bool = False,
    ) -> None:
        if not flush_interval_s > 0:
            raise RecordingError(f"flush_interval_s must be > 0 s, got {flush_interval_s!r}")
        wall_ns = time.time_ns()
        self._anchor_ns = wall_ns - time.monotonic_ns() if anchor_ns is None else int(anchor_ns)
        started = dt.datetime.fromtimestamp(wall_ns / 1e9, tz=dt.UTC)
        self.vehicle = vehicle
        self._path = resolve_path(path_or_dir, started, vehicle)
        self._sink = McapSink(self._path)
        self._flush_interval_s = float(flush_interval_s)
        self._max_queue = int(max_queue)
        # A real-time loop must never wait for the disk, so a full queue drops (and counts). A
        # simulated-time producer (a lockstep flight, far faster than real time) waits for the
        # writer instead: nothing it records is lost.
        self._block = bool(block_when_full)
        self._batch = max(1, min(self._max_queue, INLINE_BATCH))
        self._queue: deque[tuple[_Kind, str, float, Any]] = deque()
        self._wake = threading.Event()
        self._closing = False
        self._closed = False
        self._drop_lock = threading.Lock()
        self._written: dict[str, int] = {}
        self._dropped: dict[str, int] = {}
        self._rejected: dict[str, int] = {}
        self._flushes = 0
        self._error: str | None = None
        header = {
            "vehicle": vehicle,
            "software_version": software_version(),
            "started_utc": started.isoformat().replace("+00:00", "Z"),
            "anchor_ns": str(self._anchor_ns),
            **dict(metadata),
        }
        self._sink.write_metadata(METADATA_NAME, encode_metadata(header))
        self._sink.flush()
        self._display_tf_written = False
        self._taps: list[Tap] = []
        self._tap_errors = 0
        self._topic_schemas: dict[str, tuple[str, Mapping[str, Any]]] = {}
        self._last_log_ns: int | None = None
        self._reported_drops = 0
        self._next_flush = time.monotonic() + self._flush_interval_s
        self._thread: threading.Thread | None = None
        if not self._block:
            self._thread = threading.Thread(
                target=self._run, name=f"recorder-{vehicle}", daemon=True
            )
            self._thread.start()
        atexit.register(self.close)

    @property
    def path(self) -> Path:
        """The MCAP file being written."""
        return self._path

    @property
    def anchor_ns(self) -> int:
        """UTC nanoseconds at monotonic zero: log_time_ns = anchor_ns + t_s·1e9."""
        return self._anchor_ns

    def log_time_ns(self, t_s: float) -> int:
        """A monotonic time in seconds on this recording's UTC timeline, ns."""
        return self._anchor_ns + round(t_s * 1e9)

    @property
    def stats(self) -> RecorderStats:
        """A snapshot of the per-topic counters."""
        return RecorderStats(
            written=dict(self._written),
            dropped=dict(self._dropped),
            rejected=dict(self._rejected),
            queued=len(self._queue),
            flushes=self._flushes,
            error=self._error,
        )

    # The four calls below run on the producer's thread: queue only, never block (a simulated-time
    # producer writes its own batches, see the module docstring).

    def put(self, topic: str, t_s: float, payload: Any) -> None:
        """Queue a record (dataclass, dict or FoxgloveMessage) on `topic` at monotonic `t_s`."""
        if isinstance(payload, dict):
            payload = dict(payload)  # the caller may reuse its dict after this returns
        self._enqueue(_Kind.PUT, topic, t_s, payload)

    def put_raw(self, direction: Direction | str, t_s: float, data: bytes) -> None:
        """Queue one raw MAVLink frame, "rx" (from the vehicle) or "tx" (to it)."""
        try:
            topic = RAW_TOPIC_OF.get(direction)
        except TypeError:  # unhashable
            topic = None
        if topic is None:
            raise RecordingError(f"direction {direction!r}: expected 'rx' or 'tx'")
        self._enqueue(_Kind.RAW, topic, t_s, bytes(data))

    def event(self, t_s: float, level: LogLevel | int | str, text: str) -> None:
        """Queue a human-readable event as a foxglove.Log line on "/log"."""
        self._enqueue(_Kind.EVENT, LOG_TOPIC, t_s, (parse_log_level(level), str(text)))

    def add_metadata(self, name: str, data: Mapping[str, Any]) -> None:
        """Queue an extra metadata record (e.g. the parameter snapshot once it has arrived)."""
        self._enqueue(_Kind.METADATA, name, 0.0, dict(data))

    def _enqueue(self, kind: _Kind, topic: str, t_s: float, payload: Any) -> None:
        if self._closing or (not self._block and len(self._queue) >= self._max_queue):
            with self._drop_lock:
                self._dropped[topic] = self._dropped.get(topic, 0) + 1
            return
        self._queue.append((kind, topic, t_s, payload))
        if self._block and (len(self._queue) >= self._batch
                            or time.monotonic() >= self._next_flush):
            self._write_queued()

    def _write_queued(self) -> None:
        """A simulated-time producer's own writing: the whole queue, then a flush when due."""
        queue = self._queue
        while queue:
            self._write_or_drop(queue.popleft())
        now = time.monotonic()
        if now >= self._next_flush:
            self._flush()
            self._next_flush = now + self._flush_interval_s

    def _write_or_drop(self, item: Any) -> None:
        """Write a queued record, or count it dropped once the file has failed."""
        if self._error is None:
            self._write_item(*item)
        else:
            with self._drop_lock:
                self._dropped[item[1]] = self._dropped.get(item[1], 0) + 1

    def close(self) -> None:
        """Drain the queue, write the summary and index, close the file. Idempotent."""
        if self._closed:
            return
        self._closed = True
        self._closing = True
        atexit.unregister(self.close)
        self._wake.set()
        if self._thread is not None:
            self._thread.join()
        else:
            self._write_queued()
        try:
            if self._error is None:
                self._note_drops()
            self._sink.close()
        except OSError as exc:
            self._error = self._error or f"{self._path}: {exc.strerror or exc}"

    def __enter__(self) -> Recorder:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.close()

    # Writer thread.

    def _run(self) -> None:
        next_flush = time.monotonic() + self._flush_interval_s
        queue = self._queue
        while True:
            slice_end = time.perf_counter() + YIELD_AFTER_S
            while queue:
                self._write_or_drop(queue.popleft())
                if time.perf_counter() > slice_end:
                    # Hand the GIL over: a loop thread waiting for it would otherwise wait for
                    # the interpreter's switch interval (5 ms), a fifth of a control tick.
                    time.sleep(0)
                    slice_end = time.perf_counter() + YIELD_AFTER_S
            now = time.monotonic()
            if self._closing and not queue:
                break
            if now >= next_flush:
                self._flush()
                next_flush = now + self._flush_interval_s
            self._wake.wait(timeout=min(0.02, max(0.0, next_flush - now)))
            self._wake.clear()

    def _flush(self) -> None:
        if self._error is not None:
            return
        try:
            self._note_drops()
            self._sink.flush()
            self._flushes += 1
        except OSError as exc:
            self._error = f"{self._path}: {exc.strerror or exc}"

    def _note_drops(self) -> None:
        """Put new drops in the file itself as a warning, so a reader sees the hole."""
        with self._drop_lock:
            total = sum(self._dropped.values())
        if total > self._reported_drops and self._last_log_ns is not None:
            text = (
                f"recorder queue full: dropped {total - self._reported_drops} messages "
                f"({total} in all)"
            )
            message = foxglove_log(LogLevel.WARNING, text, self.vehicle)
            self._write_foxglove(LOG_TOPIC, self._last_log_ns, message)
            self._written[LOG_TOPIC] = self._written.get(LOG_TOPIC, 0) + 1
            self._reported_drops = total

    def _write_item(self, kind: _Kind, topic: str, t_s: float, payload: Any) -> None:
        try:
            if kind is _Kind.METADATA:
                self._sink.write_metadata(topic, encode_metadata(payload))
                return
            log_ns = self._anchor_ns + round(t_s * 1e9)
            self._last_log_ns = log_ns
            if not self._display_tf_written:
                # once, at the first message's time, so it spans the flight's timeline
                self._write_foxglove(TF_TOPIC, log_ns, ned_display_transform())
                self._written[TF_TOPIC] = 1
                self._display_tf_written = True
            if kind is _Kind.RAW:
                if not self._sink.has_topic(topic):
                    self._add_topic(topic, RAW_FRAME_SCHEMA_NAME, RAW_FRAME_SCHEMA)
                # what encode_json makes of {"data": base64, "len": n}, without its cost on
                # every frame: base64's alphabet needs no JSON escaping
                self._write_bytes(topic, log_ns, b'{"data":"' + base64.b64encode(payload)
                                  + b'","len":' + str(len(payload)).encode() + b"}")
            elif kind is _Kind.EVENT:
                level, text = payload
                self._write_foxglove(topic, log_ns, foxglove_log(level, text, self.vehicle))
            elif isinstance(payload, FoxgloveMessage):
                self._write_foxglove(topic, log_ns, payload)
            else:
                self._write_record(topic, log_ns, payload)
        except OSError as exc:
            self._error = f"{self._path}: {exc.strerror or exc}"
            self._dropped[topic] = self._dropped.get(topic, 0) + 1
            return
        except Exception:
            # A payload that cannot be written (wrong type, infinite time, unencodable value)
            # is counted and skipped: one bad record must not stop the flight's recording.
            self._rejected[topic] = self._rejected.get(topic, 0) + 1
            return
        self._written[topic] = self._written.get(topic, 0) + 1

    def add_tap(self, tap: Tap) -> None:
        """Also hand every message, once written, to `tap(topic, schema name, schema, log time
        ns, JSON bytes)` on the writer thread (the live view: it reuses the recording's JSON
        instead of encoding every message a second time). Call before the first put."""
        self._taps.append(tap)

    def _add_topic(self, topic: str, schema_name: str, schema: Mapping[str, Any]) -> None:
        self._sink.add_topic(topic, schema_name, schema)
        self._topic_schemas[topic] = (schema_name, schema)

    def _write(self, topic: str, log_ns: int, message: Mapping[str, Any]) -> None:
        self._write_bytes(topic, log_ns, encode_json(message))

    def _write_bytes(self, topic: str, log_ns: int, data: bytes) -> None:
        self._sink.write_bytes(topic, log_ns, data)
        if self._taps:
            name, schema = self._topic_schemas[topic]
            for tap in self._taps:
                try:
                    tap(topic, name, schema, log_ns, data)
                except Exception:  # a live view's trouble must never cost the recording
                    self._tap_errors += 1

    def _write_foxglove(self, topic: str, log_ns: int, message: FoxgloveMessage) -> None:
        if not self._sink.has_topic(topic):
            self._add_topic(topic, message.schema_name, WELL_KNOWN_SCHEMAS[message.schema_name])
        self._write(topic, log_ns, stamped(message, log_ns))

    def _write_record(self, topic: str, log_ns: int, payload: Any) -> None:
        if not (isinstance(payload, Mapping) or dataclasses.is_dataclass(payload)):
            raise TypeError(f"payload on {topic} must be a dataclass or a dict")
        message = to_jsonable(payload)
        if not self._sink.has_topic(topic):
            name, schema = schema_for_payload(payload, message)
            self._add_topic(topic, name or schema_name_for_topic(topic), schema)
        self._write(topic, log_ns, message)
