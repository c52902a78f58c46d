"""A live view of a flight over Foxglove's WebSocket protocol (the `foxglove-sdk` server).

The same topics, schemas and JSON as the recording: `put`, `put_raw` and `event` have the
recorder's signatures and, like it, only append to a queue on the caller's thread (the 25 ms
loop's). A worker thread turns the records into JSON and hands them to the server, whose own
threads (native code, outside the GIL) talk to the clients. Every channel is advertised with its
JSON Schema under the recording's schema name, so the well-known `foxglove.*` messages go out as
JSON that validates against Foxglove's official schemas, not as the SDK's protobuf.

Time: log times are `anchor_ns + t_s·1e9` as in the recording; pass the recorder's anchor so a
live client and the file agree to the nanosecond.
"""

from __future__ import annotations

import base64
import dataclasses
import json
import threading
import time
from collections import deque
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from logs.encoding import encode_json, schema_for_payload, to_jsonable
from logs.errors import RecordingError
from logs.foxglove import (
    FoxgloveMessage,
    LogLevel,
    foxglove_log,
    ned_display_transform,
    stamped,
)
from logs.foxglove_schemas import WELL_KNOWN_SCHEMAS
from logs.mcap_sink import schema_name_for_topic
from logs.topics import LOG_TOPIC, MAVLINK_RX_TOPIC, MAVLINK_TX_TOPIC, TF_TOPIC

DEFAULT_HOST = "127.0.0.1"  # a flight is shown on this machine unless the pilot opens it up
DEFAULT_PORT = 8765
SUBPROTOCOL = "foxglove.sdk.v1"
YIELD_AFTER_S = 0.0002  # worker time slice before it hands the GIL back to the loop
WAKE_EVERY_S = 0.05
DISPLAY_TF_EVERY_S = 1.0  # a client that joins late still gets the world → ned transform
# Per client, the server drops its oldest data message once this many wait to go out. The SDK's
# 1024 is about 2 s of a flight's subscribed topics at replay speed 2: a viewer on a busy PC
# stalls that long and loses the middle of a flight. Messages are a few hundred bytes each.
BACKLOG_MESSAGES = 16_384
# The SDK has no flush, and a client of a finished replay was seen to miss its last messages.
# Closing waits this long for the server's senders while a client is subscribed.
CLOSE_LINGER_S = 0.5
RAW_FRAME_SCHEMA_NAME = "quadgcs.MavlinkFrame"
_RAW_SCHEMA: dict[str, Any] = {
    "type": "object",
    "title": "MAVLink frame",
    "description": "One raw MAVLink frame as it crossed the link, base64",
    "properties": {
        "data": {"type": "string", "contentEncoding": "base64"},
        "len": {"type": "integer", "minimum": 0},
    },
}
_RAW_TOPICS = {"rx": MAVLINK_RX_TOPIC, "tx": MAVLINK_TX_TOPIC}


def parse_address(text: str) -> tuple[str, int]:
    """`[HOST:]PORT` → (host, port); RecordingError with one line when it is not one."""
    host, sep, port_text = text.rpartition(":")
    host = host.strip("[]") if sep else DEFAULT_HOST
    try:
        port = int(port_text)
    except ValueError:
        port = -1
    if not 0 <= port <= 65535 or (sep and not host):
        raise RecordingError(f"--foxglove {text!r}: expected [HOST:]PORT, e.g. 8765 or "
                             "0.0.0.0:8765 (port 0..65535, 0 = any free port)")
    return host, port


@dataclass(frozen=True, slots=True)
class LiveStats:
    """What the live view did: messages handed to the server, dropped (queue full), rejected
    (unencodable), and the channels advertised."""

    published: int
    dropped: int
    rejected: int
    channels: int


class LiveView:
    """Serve one flight (or a replay) live to Foxglove clients (see the module docstring)."""

    def __init__(self, host: str = DEFAULT_HOST, port: int = DEFAULT_PORT, *,
                 name: str = "quadgcs", anchor_ns: int | None = None,
                 max_queue: int = 50_000) -> None:
        import foxglove

        self._foxglove = foxglove
        self._anchor_ns = (time.time_ns() - time.monotonic_ns() if anchor_ns is None
                           else int(anchor_ns))
        self._context = foxglove.Context()  # own channels: several views may share a process
        try:
            self._server = foxglove.start_server(name=name, host=host, port=port,
                                                 context=self._context,
                                                 message_backlog_size=BACKLOG_MESSAGES)
        except Exception as exc:  # the SDK raises its own error type for a busy or bad address
            raise RecordingError(f"--foxglove {host}:{port}: cannot serve: {exc}") from None
        self.host = host
        self.port = int(self._server.port)
        self._max_queue = int(max_queue)
        self._queue: deque[tuple[str, str, int, Any]] = deque()
        self._wake = threading.Event()
        self._closing = False
        self._closed = False
        self._channels: dict[str, Any] = {}
        self._published = 0
        self._dropped = 0
        self._rejected = 0
        self._last_tf_ns: int | None = None
        self._create_lock = threading.Lock()
        self._thread = threading.Thread(target=self._run, name="foxglove-live", daemon=True)
        self._thread.start()

    @classmethod
    def open(cls, address: str, **kwargs: Any) -> LiveView:
        """A live view on `[HOST:]PORT`."""
        host, port = parse_address(address)
        return cls(host, port, **kwargs)

    @property
    def url(self) -> str:
        """Where Foxglove connects: ws://HOST:PORT."""
        return f"ws://{self.host}:{self.port}"

    @property
    def anchor_ns(self) -> int:
        """UTC nanoseconds at monotonic zero: log_time_ns = anchor_ns + t_s·1e9."""
        return self._anchor_ns

    @property
    def stats(self) -> LiveStats:
        """A snapshot of the counters."""
        return LiveStats(self._published, self._dropped, self._rejected, len(self._channels))

    # Called on the loop's thread: queue only.

    def put(self, topic: str, t_s: float, payload: Any) -> None:
        """Queue a record (dataclass, dict or FoxgloveMessage) on `topic` at monotonic `t_s`."""
        if isinstance(payload, dict):
            payload = dict(payload)  # the caller may reuse its dict after this returns
        self._enqueue("put", topic, self._anchor_ns + round(t_s * 1e9), payload)

    def put_raw(self, direction: str, t_s: float, data: bytes) -> None:
        """Queue one raw MAVLink frame, "rx" (from the vehicle) or "tx" (to it)."""
        topic = _RAW_TOPICS.get(getattr(direction, "value", direction), MAVLINK_RX_TOPIC)
        self._enqueue("raw", topic, self._anchor_ns + round(t_s * 1e9), bytes(data))

    def event(self, t_s: float, level: LogLevel | int, text: str) -> None:
        """Queue a human-readable event as a foxglove.Log line on "/log"."""
        message = foxglove_log(LogLevel(int(level)), str(text), "quadgcs")
        self._enqueue("put", LOG_TOPIC, self._anchor_ns + round(t_s * 1e9), message)

    def publish(self, topic: str, schema_name: str, schema: Mapping[str, Any] | bytes,
                log_ns: int, data: bytes) -> None:
        """Send an already-encoded JSON message with its schema now, on the caller's thread
        (the recorder's writer, or a replay): no second Python thread wakes for it, and the
        server's native code takes it from here. Dropped when nobody subscribed."""
        if self._closed:
            self._dropped += 1
            return
        try:
            self._maybe_display_tf(log_ns)
            channel = self._channel(topic, schema_name, schema)
            if channel.has_sinks():
                channel.log(data, log_time=int(log_ns))
                self._published += 1
        except Exception:  # an odd message is counted; the caller (the recorder) goes on
            self._rejected += 1

    def _enqueue(self, kind: str, topic: str, log_ns: int, payload: Any) -> None:
        if self._closing or len(self._queue) >= self._max_queue:
            self._dropped += 1
            return
        self._queue.append((kind, topic, log_ns, payload))

    def close(self) -> None:
        """Send what is queued, stop the worker and the server. Idempotent."""
        if self._closed:
            return
        self._closed = True
        self._closing = True
        self._wake.set()
        self._thread.join()
        if any(channel.has_sinks() for channel in self._channels.values()):
            time.sleep(CLOSE_LINGER_S)
        for channel in self._channels.values():
            channel.close()
        self._server.stop()

    def __enter__(self) -> LiveView:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # Worker thread.

    def _run(self) -> None:
        queue = self._queue
        while True:
            slice_end = time.perf_counter() + YIELD_AFTER_S
            while queue:
                self._publish_item(*queue.popleft())
                if time.perf_counter() > slice_end:
                    # Hand the GIL over: the loop thread waiting for it would otherwise wait
                    # for the interpreter's switch interval, a fifth of a control tick.
                    time.sleep(0)
                    slice_end = time.perf_counter() + YIELD_AFTER_S
            if self._closing and not queue:
                return
            # woken on a timer, not per message: one wake-up per batch keeps the GIL off the
            # loop's thread except in a few short slices a second
            self._wake.wait(timeout=WAKE_EVERY_S)
            self._wake.clear()

    def _channel(self, topic: str, schema_name: str, schema: Mapping[str, Any] | bytes) -> Any:
        channel = self._channels.get(topic)
        if channel is None:
            with self._create_lock:  # the worker and a publishing thread may both get here
                channel = self._channels.get(topic)
                if channel is None:
                    fg = self._foxglove
                    data = schema if isinstance(schema, bytes) else json.dumps(schema).encode()
                    channel = fg.Channel(
                        topic, schema=fg.Schema(name=schema_name, encoding="jsonschema",
                                                data=data),
                        message_encoding="json", context=self._context)
                    self._channels[topic] = channel
        return channel

    def _maybe_display_tf(self, log_ns: int) -> None:
        last = self._last_tf_ns
        if last is None or log_ns - last >= DISPLAY_TF_EVERY_S * 1e9:
            self._last_tf_ns = log_ns
            self._send_foxglove(TF_TOPIC, log_ns, ned_display_transform())

    def _publish_item(self, kind: str, topic: str, log_ns: int, payload: Any) -> None:
        try:
            self._maybe_display_tf(log_ns)
            if kind == "raw":
                channel = self._channel(topic, RAW_FRAME_SCHEMA_NAME, _RAW_SCHEMA)
                if channel.has_sinks():  # nobody subscribed: skip the base64 and JSON
                    msg = {"data": base64.b64encode(payload).decode("ascii"), "len": len(payload)}
                    channel.log(encode_json(msg), log_time=log_ns)
            elif isinstance(payload, FoxgloveMessage):
                self._send_foxglove(topic, log_ns, payload)
            else:
                self._send_record(topic, log_ns, payload)
        except Exception:
            # a payload that cannot be encoded is counted and skipped, as the recorder does:
            # one bad record must not end the live view
            self._rejected += 1
            return
        self._published += 1

    def _send_foxglove(self, topic: str, log_ns: int, message: FoxgloveMessage) -> None:
        channel = self._channel(topic, message.schema_name,
                                WELL_KNOWN_SCHEMAS[message.schema_name])
        if channel.has_sinks():
            channel.log(encode_json(stamped(message, log_ns)), log_time=log_ns)

    def _send_record(self, topic: str, log_ns: int, payload: Any) -> None:
        if not (isinstance(payload, Mapping) or dataclasses.is_dataclass(payload)):
            raise TypeError(f"payload on {topic} must be a dataclass or a dict")
        channel = self._channels.get(topic)
        if channel is not None and not channel.has_sinks():
            return
        message = to_jsonable(payload)
        if channel is None:
            name, schema = schema_for_payload(payload, message)
            channel = self._channel(topic, name or schema_name_for_topic(topic), schema)
        channel.log(encode_json(message), log_time=log_ns)
