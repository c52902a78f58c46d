"""MAVLink forwarding: other ground stations watch, and talk to, the vehicle through this link.

    fwd = Forwarder.open(["udpout:127.0.0.1:14550", "tcpin:0.0.0.0:5760"])
    link = VehicleLink.open(url, forward=fwd.port(None))

This is what MAVProxy's `--out` does for pilots who keep QGroundControl or Mission Planner
watching while a script flies, with one difference: only one writer of sticks at a time.

- Every frame from the vehicle goes to every station unchanged: its sequence number, its
  signature and its sender's ids, so a station that checks signatures can check these.
- A station's frames go to the vehicle unchanged (parameters, commands, mission items), except:
  - RC_CHANNELS_OVERRIDE while this station writes the sticks: the vehicle would obey whichever
    override came last, so two writers would fight over the throttle;
  - anything while this station is silent (the link-loss policy): a forwarded station's
    heartbeat carries the same GCS id and would reset the very failsafe the silence is for;
  - unsigned or badly signed frames while the vehicle link signs: refused as this link refuses
    them from the vehicle;
  - stream-rate requests (REQUEST_DATA_STREAM, SET_MESSAGE_INTERVAL): the firmware keeps one
    set of rates per port, so MAVProxy's default 4 Hz request (or QGroundControl's) would starve
    the 25 ms loop of the 40 Hz it set up; the other station gets every frame at that rate.
  Each refusal is counted and the first of each kind (and then one every `NOTE_EVERY_S`) is
  reported, so the pilot sees why the other station's sticks do nothing.
- Several vehicles can share one forwarder (`port(sysid)` per link): a frame addressed to one
  system goes to that vehicle's link only, a broadcast (target 0 or no target) to all.
"""

from __future__ import annotations

import enum
import threading
from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from firmware_link.errors import LinkUsageError
from firmware_link.forward_peers import (
    READ_BUDGET_BYTES,
    PeerConn,
    PeerSocket,
    parse_forward_url,
)

NOTE_EVERY_S = 5.0
# frames a link that stopped polling may have waiting; older ones are stale commands
PORT_QUEUE_FRAMES = 256
_SIGNATURE_REASON = "Invalid signature"
_PREFIX_REASON = "Bad prefix"


class Refusal(enum.Enum):
    """Why a forwarded station's frame did not go to the vehicle."""

    OVERRIDE = "RC override refused: quadgcs is writing the sticks"
    SILENT = "frame held back: quadgcs is silent so the vehicle's own failsafe can act"
    UNSIGNED = "unsigned or badly signed frame refused: the vehicle link signs"
    STREAMS = "stream-rate request refused: quadgcs set the rates its loop needs"


_COUNTER = {Refusal.OVERRIDE: "refused_overrides", Refusal.SILENT: "refused_silent",
            Refusal.UNSIGNED: "refused_unsigned", Refusal.STREAMS: "refused_streams"}
MAV_CMD_SET_MESSAGE_INTERVAL = 511


@dataclass(frozen=True, slots=True)
class ForwardStats:
    """Counters of one forwarder since it opened."""

    endpoints: tuple[str, ...] = ()  # the URLs, with the ports actually bound
    stations: int = 0  # stations that can hear the vehicle now
    to_stations: int = 0  # frames sent out (one per frame per endpoint)
    to_stations_dropped: int = 0  # frames a station's socket would not take
    to_vehicle: int = 0  # stations' frames passed to a vehicle link
    refused_overrides: int = 0
    refused_silent: int = 0
    refused_unsigned: int = 0
    refused_streams: int = 0
    bad_frames: int = 0  # garbage and bad CRCs from stations

    @property
    def summary(self) -> str:
        """One line for a status bar or a log."""
        refused = (self.refused_overrides + self.refused_silent + self.refused_unsigned
                   + self.refused_streams)
        return (f"forward {', '.join(self.endpoints)}: {self.stations} station(s), "
                f"{self.to_stations} out, {self.to_vehicle} in, "
                f"{self.refused_overrides} override(s) refused, {refused} refused in all")


class _Kind(enum.Enum):
    """What the policy needs to know of a station's frame."""

    OVERRIDE = "override"
    STREAMS = "streams"
    OTHER = "other"


def _kind(msg: Any) -> _Kind:
    kind = msg.get_type()
    if kind == "RC_CHANNELS_OVERRIDE":
        return _Kind.OVERRIDE
    if kind == "REQUEST_DATA_STREAM" or (
            kind in ("COMMAND_LONG", "COMMAND_INT")
            and int(msg.command) == MAV_CMD_SET_MESSAGE_INTERVAL):
        return _Kind.STREAMS
    return _Kind.OTHER


class Forwarder:
    """The `--forward` endpoints of a session, shared by its vehicle links."""

    def __init__(self, sockets: list[PeerSocket]) -> None:
        self._sockets = sockets
        self._lock = threading.RLock()  # counters are bumped inside pump() too
        self._ports: list[ForwardPort] = []
        self._counts: dict[str, int] = {}
        self._closed = False

    @classmethod
    def open(cls, urls: Sequence[str]) -> Forwarder:
        """Bind or address every URL; LinkUsageError/LinkError naming the one that failed."""
        if not urls:
            raise LinkUsageError("--forward: no URL given")
        specs = [parse_forward_url(u) for u in urls]
        sockets: list[PeerSocket] = []
        try:
            for spec in specs:
                sockets.append(PeerSocket(spec))
        except BaseException:
            for s in sockets:
                s.close()
            raise
        return cls(sockets)

    @property
    def urls(self) -> tuple[str, ...]:
        """The endpoints, with port 0 replaced by the port the system picked."""
        return tuple(f"{s.spec.kind.value}:{s.spec.host}:{s.spec.port or s.bound_port}"
                     for s in self._sockets)

    def port(self, sysid: int | None) -> ForwardPort:
        """The part one vehicle link uses (None: every frame, whatever its target)."""
        p = ForwardPort(self, sysid)
        with self._lock:
            self._ports.append(p)
        return p

    def count(self, key: str, n: int = 1) -> None:
        """Add to a counter."""
        with self._lock:
            self._counts[key] = self._counts.get(key, 0) + n

    @property
    def stats(self) -> ForwardStats:
        """A snapshot of the counters."""
        c = self._counts.get
        return ForwardStats(
            endpoints=self.urls,
            stations=sum(s.connected for s in self._sockets),
            to_stations=c("to_stations", 0),
            to_stations_dropped=c("to_stations_dropped", 0),
            to_vehicle=c("to_vehicle", 0),
            refused_overrides=c("refused_overrides", 0),
            refused_silent=c("refused_silent", 0),
            refused_unsigned=c("refused_unsigned", 0),
            refused_streams=c("refused_streams", 0),
            bad_frames=c("bad_frames", 0),
        )

    def send(self, frame: bytes) -> None:
        """One vehicle frame to every station."""
        with self._lock:
            if self._closed:
                return
            for s in self._sockets:
                dropped = s.send(frame)
                self.count("to_stations")
                if dropped:
                    self.count("to_stations_dropped", dropped)

    def pump(self, key: bytes | None) -> None:
        """Read what the stations sent and queue each good frame for the links it is for."""
        with self._lock:
            if self._closed:
                return
            budget = READ_BUDGET_BYTES
            for s in self._sockets:
                for peer, data in s.read(budget):
                    budget -= len(data)
                    self._parse(peer, data, key)

    def _parse(self, peer: PeerConn, data: bytes, key: bytes | None) -> None:
        peer.set_key(key)
        for msg in peer.parse(data):
            if msg.get_type() == "BAD_DATA":
                reason = str(getattr(msg, "reason", ""))
                if reason == _SIGNATURE_REASON:
                    self.count(_COUNTER[Refusal.UNSIGNED])
                    for p in self._ports:
                        p.note(Refusal.UNSIGNED)
                elif reason != _PREFIX_REASON:
                    self.count("bad_frames")
                continue
            target = int(getattr(msg, "target_system", 0) or 0)
            for p in self._ports:
                if p.sysid is None or target in (0, p.sysid):
                    p.queue.append((_kind(msg), bytes(msg.get_msgbuf())))

    def close(self) -> None:
        """Close every endpoint. Idempotent."""
        with self._lock:
            if self._closed:
                return
            self._closed = True
            for s in self._sockets:
                s.close()


class ForwardPort:
    """One vehicle link's side of a forwarder."""

    def __init__(self, forwarder: Forwarder, sysid: int | None) -> None:
        self.forwarder = forwarder
        self.sysid = sysid
        self.queue: deque[tuple[_Kind, bytes]] = deque(maxlen=PORT_QUEUE_FRAMES)
        self._pending_notes: list[Refusal] = []
        self._last_note_s: dict[Refusal, float] = {}

    def to_stations(self, frame: bytes) -> None:
        """A frame the vehicle sent, to every station, unchanged."""
        self.forwarder.send(frame)

    def refuse(self, why: Refusal) -> None:
        """Count a refusal and remember to report it."""
        self.forwarder.count(_COUNTER[why])
        self.note(why)

    def note(self, why: Refusal) -> None:
        """Remember to report a refusal (counted by the caller)."""
        self._pending_notes.append(why)

    def from_stations(self, *, now_s: float, sticks_owned: bool, silent: bool,
                      signing_key: bytes | None) -> tuple[list[bytes], list[str]]:
        """The stations' frames that may go to the vehicle now, and refusals to report."""
        self.forwarder.pump(signing_key)
        out: list[bytes] = []
        while self.queue:
            kind, frame = self.queue.popleft()
            if silent:
                self.refuse(Refusal.SILENT)
            elif kind is _Kind.STREAMS:
                self.refuse(Refusal.STREAMS)
            elif kind is _Kind.OVERRIDE and sticks_owned:
                self.refuse(Refusal.OVERRIDE)
            else:
                out.append(frame)
        if out:
            self.forwarder.count("to_vehicle", len(out))
        return out, self._notes(now_s)

    def _notes(self, now_s: float) -> list[str]:
        notes: list[str] = []
        for why in dict.fromkeys(self._pending_notes):
            last = self._last_note_s.get(why)
            if last is None or now_s - last >= NOTE_EVERY_S:
                self._last_note_s[why] = now_s
                notes.append(f"forwarded station: {why.value} ({self.forwarder.stats.summary})")
        self._pending_notes.clear()
        return notes

    @property
    def stats(self) -> ForwardStats:
        """The forwarder's counters."""
        return self.forwarder.stats
