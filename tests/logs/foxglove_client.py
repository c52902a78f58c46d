"""A minimal Foxglove WebSocket client (the `websockets` package) for the live-view tests.

It speaks what foxglove-sdk 0.30 serves under the subprotocol `foxglove.sdk.v1`: JSON text
frames for control (`serverInfo`, `advertise`, `unadvertise`), binary frames for data (opcode 1,
subscription id u32, log time u64 little-endian, then the message bytes).
"""

from __future__ import annotations

import asyncio
import json
import struct
import time
from dataclasses import dataclass, field
from typing import Any

import websockets

SUBPROTOCOL = "foxglove.sdk.v1"
MESSAGE_DATA = 0x01


@dataclass
class Received:
    """Messages received per topic, in arrival order: (log time ns, decoded JSON)."""

    by_topic: dict[str, list[tuple[int, Any]]] = field(default_factory=dict)
    schema_names: dict[str, str] = field(default_factory=dict)
    encodings: dict[str, str] = field(default_factory=dict)


class FoxgloveClient:
    """Connect, subscribe to topics as they are advertised, decode what arrives."""

    def __init__(self, url: str, topics: set[str]) -> None:
        self.url = url
        self.topics = topics
        self.received = Received()
        self._subs: dict[int, str] = {}
        self._ws: Any = None

    async def __aenter__(self) -> FoxgloveClient:
        self._ws = await websockets.connect(self.url, subprotocols=[SUBPROTOCOL], max_size=None)
        return self

    async def __aexit__(self, *exc: object) -> None:
        await self._ws.close()

    @property
    def subprotocol(self) -> str | None:
        """What the server agreed to speak."""
        return self._ws.subprotocol

    async def _handle(self, frame: str | bytes) -> None:
        if isinstance(frame, str):
            msg = json.loads(frame)
            if msg.get("op") == "advertise":
                subs = []
                for ch in msg["channels"]:
                    if ch["topic"] in self.topics and ch["topic"] not in self._subs.values():
                        sid = len(self._subs) + 1
                        self._subs[sid] = ch["topic"]
                        self.received.schema_names[ch["topic"]] = ch["schemaName"]
                        self.received.encodings[ch["topic"]] = ch["encoding"]
                        subs.append({"id": sid, "channelId": ch["id"]})
                if subs:
                    await self._ws.send(json.dumps({"op": "subscribe", "subscriptions": subs}))
            return
        if frame[0] != MESSAGE_DATA:
            return
        sid, log_ns = struct.unpack_from("<IQ", frame, 1)
        topic = self._subs.get(sid)
        if topic is not None:
            self.received.by_topic.setdefault(topic, []).append(
                (log_ns, json.loads(frame[13:])))

    async def run_until(self, done: Any, timeout_s: float) -> bool:
        """Receive until `done(received)` holds (True) or the deadline passes (False)."""
        deadline = time.monotonic() + timeout_s
        while not done(self.received):
            left = deadline - time.monotonic()
            if left <= 0:
                return False
            try:
                frame = await asyncio.wait_for(self._ws.recv(), left)
            except (TimeoutError, websockets.ConnectionClosed):
                return done(self.received)
            await self._handle(frame)
        return True
