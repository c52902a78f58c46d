"""Lockstep: the simulation on its caller's clock, behind in-memory byte ports.

A station in the same process owns time. `advance_to(t_s)` runs every vehicle's 100 Hz tick up
to `t_s` and moves what each tick sent into the ports, as the socket server flushes its
endpoints after every tick; bytes a station writes reach the vehicle at once, at the current
simulated time, as the server reads its sockets between ticks. Waiting for bytes
(`MemoryPort.wait_readable`) is letting simulated time pass. Nothing here reads the wall clock,
sleeps or starts a thread, so a flight runs as fast as the CPU allows and repeats bit for bit
from its seed.

What crosses a port is MAVLink, the frames the TCP endpoints send (`Channel`, `MocapEncoder`,
`TruthEncoder`): the station decodes them with its own codec and learns nothing else about the
simulation. A port behaves as the TCP endpoint does: unthrottled, and a reader that falls more
than `PORT_BACKLOG_BYTES` behind loses what does not fit.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Protocol

import numpy as np

from sitl.autopilot import AutopilotOptions, Profile
from sitl.fault_frames import FrameSplitter
from sitl.link.channel import Channel
from sitl.mocap_server import MocapEncoder
from sitl.params import ParamError
from sitl.simulation import Simulation
from sitl.truth_server import TruthEncoder
from sitl.world import World, default_world, load_world, world_from_toml

PORT_BACKLOG_BYTES = 65536  # as the TCP endpoint's backlog (sitl.link.endpoints)
_EPS_S = 1e-9


class PortClosed(OSError):
    """The port was closed (by either side)."""


FADES = ("none", "down", "up", "both")


@dataclass(frozen=True, slots=True)
class LinkFaults:
    """What a vehicle port suffers, on simulated time (the fault proxy's faults, in lockstep).

    `fade` loses every byte of one way ("down": vehicle to station, "up", or "both") from
    `fade_start_s` for `fade_s` simulated seconds, a radio fade; `loss` loses each whole frame
    with that probability both ways, from the port's own seeded generator, from `loss_start_s`
    for `loss_s` seconds (by default from power-on, for ever). A frame with a flipped bit is a
    lost frame to its reader (the checksum fails), so the fault proxy's loss and flips are one
    `loss` here."""

    loss: float = 0.0
    fade: str = "none"
    fade_start_s: float = 0.0
    fade_s: float = 0.0
    seed: int = 0
    loss_start_s: float = 0.0
    loss_s: float = math.inf

    def __post_init__(self) -> None:
        if self.fade not in FADES:
            raise ValueError(f"fade {self.fade!r}: expected one of {', '.join(FADES)}")
        if not 0.0 <= self.loss < 1.0:
            raise ValueError(f"loss {self.loss}: expected a probability in [0, 1)")
        if min(self.fade_s, self.fade_start_s, self.loss_s, self.loss_start_s) < 0.0:
            raise ValueError("fade_start_s, fade_s, loss_start_s and loss_s: expected seconds "
                             ">= 0")

    def lossy(self, t_s: float) -> bool:
        """Whether frames are being lost at `t_s`."""
        return (self.loss > 0.0
                and self.loss_start_s <= t_s < self.loss_start_s + self.loss_s)

    def loss_at(self, way: str, t_s: float) -> float:
        """The probability that a frame going `way` ("down" or "up") is lost at `t_s`."""
        return self.loss if self.lossy(t_s) else 0.0

    def faded(self, way: str, t_s: float) -> bool:
        """Whether way "down" or "up" is in its fade at `t_s`."""
        return (self.fade in (way, "both")
                and self.fade_start_s <= t_s < self.fade_start_s + self.fade_s)


@dataclass(frozen=True, slots=True)
class Stall:
    """The whole SITL stopped for `stop_s` of every `every_s` simulated seconds, from
    `start_s` on, as a loaded machine stops a SITL process (SIGSTOP, SIGCONT): its vehicles,
    motion capture and truth neither fly nor send, and on waking it runs the ticks it missed at
    once, so everything they sent arrives in one burst. Its clock is the station's, so the
    stall falls at the same moments of a flight for every run of a seed."""

    stop_s: float
    every_s: float
    start_s: float = 0.0

    def __post_init__(self) -> None:
        if not 0.0 < self.stop_s < self.every_s or self.start_s < 0.0:
            raise ValueError(f"stall {self.stop_s} s of every {self.every_s} s from "
                             f"{self.start_s} s: expected 0 < stop < every and start >= 0")

    def _stopped_at(self, t_s: float) -> float | None:
        """When the stop that `t_s` falls in began; None if the SITL runs at `t_s`."""
        if t_s < self.start_s:
            return None
        k = math.floor((t_s - self.start_s) / self.every_s)
        begin = self.start_s + (k + 1) * self.every_s - self.stop_s
        return begin if begin <= t_s else None

    def resumes_s(self, t_s: float) -> float:
        """The earliest time at or after `t_s` at which the SITL runs."""
        begin = self._stopped_at(t_s)
        return t_s if begin is None else begin + self.stop_s

    def reached_s(self, t_s: float) -> float:
        """How far the SITL's own time has run when the clock reads `t_s`: `t_s`, or the
        moment it was stopped."""
        begin = self._stopped_at(t_s)
        return t_s if begin is None else begin


class Stopping(Protocol):
    """What the clock asks of a stalled SITL (`Stall`, or a fault search's stalls)."""

    def resumes_s(self, t_s: float) -> float: ...

    def reached_s(self, t_s: float) -> float: ...


class PortFaults(Protocol):
    """What a faulty port asks of its faults (`LinkFaults`, or a fault search's schedule)."""

    @property
    def seed(self) -> int: ...

    def faded(self, way: str, t_s: float) -> bool: ...

    def loss_at(self, way: str, t_s: float) -> float: ...


class _Lossy:
    """One way of a faulty port: whole frames through or lost, as the faults say."""

    def __init__(self, faults: PortFaults, way: str, rng: np.random.Generator) -> None:
        self.faults = faults
        self.way = way
        self._rng = rng
        self._split = FrameSplitter()
        self.lost_frames = 0

    def through(self, data: bytes, t_s: float) -> bytes:
        """What of `data` gets across at `t_s`."""
        f = self.faults
        if f.faded(self.way, t_s):
            self.lost_frames += sum(ok for ok, _ in self._split.feed(data))
            return b""
        loss = f.loss_at(self.way, t_s)
        if loss <= 0.0:
            return data
        out = bytearray()
        for ok, chunk in self._split.feed(data):
            if ok and self._rng.random() < loss:
                self.lost_frames += 1
            else:
                out += chunk
        return bytes(out)


class MemoryPort:
    """One connection point: what the simulation sent waits here until read; what is written
    goes to the simulation at once."""

    def __init__(self, owner: LockstepSitl, name: str,
                 receive: Callable[[bytes], None] | None,
                 faults: PortFaults | None = None) -> None:
        self.owner = owner
        self.name = name
        self._receive = receive
        self._rx = bytearray()
        self.dropped_bytes = 0
        self.closed = False
        self.connected = False  # as a TCP endpoint: nothing is sent before a client comes
        self._down = self._up = None
        if faults is not None:
            down, up = np.random.default_rng(faults.seed).spawn(2)
            self._down, self._up = _Lossy(faults, "down", down), _Lossy(faults, "up", up)

    @property
    def lost_frames(self) -> tuple[int, int]:
        """Frames the faults lost (down, up)."""
        return (self._down.lost_frames if self._down else 0,
                self._up.lost_frames if self._up else 0)

    def connect(self) -> None:
        """A client opened the port: from now on it gets what the simulation sends (before,
        nobody was there to get it, as with a TCP endpoint that has no client)."""
        self.connected = True

    def deliver(self, data: bytes) -> None:
        """Queue bytes for the reader (dropped when it is that far behind)."""
        if not self.connected or self.closed or not data:
            return
        if self._down is not None:
            data = self._down.through(data, self.owner.t_s)
        if not data:
            return
        if len(self._rx) + len(data) > PORT_BACKLOG_BYTES:
            self.dropped_bytes += len(data)
            return
        self._rx += data

    @property
    def readable(self) -> bool:
        """Bytes are waiting."""
        return bool(self._rx)

    def read(self, max_bytes: int) -> bytes:
        """Up to `max_bytes` of what waits; PortClosed once closed."""
        if self.closed:
            raise PortClosed(f"{self.name}: closed")
        out = bytes(self._rx[:max_bytes])
        del self._rx[:max_bytes]
        return out

    def write(self, data: bytes | memoryview) -> int:
        """Hand `data` to the simulation (all of it); PortClosed once closed."""
        if self.closed:
            raise PortClosed(f"{self.name}: closed")
        sent = bytes(data)
        if self._up is not None:
            sent = self._up.through(sent, self.owner.t_s)
        if self._receive is not None and sent:
            self._receive(sent)
        return len(data)

    def wait_readable(self, timeout_s: float) -> None:
        """Let simulated time pass until bytes wait or `timeout_s` has passed."""
        self.owner.advance_until(lambda: bool(self._rx) or self.closed, timeout_s)

    def close(self) -> None:
        """Close the port (idempotent); the simulation stops feeding it."""
        self.closed = True
        self._rx.clear()


class LockstepSitl:
    """A `Simulation` advanced by its caller, with in-memory vehicle, mocap and truth ports."""

    def __init__(self, world: World, profile: Profile = Profile.APM25, n_vehicles: int = 1,
                 seed: int = 0, noise: bool = True, signing_key: bytes | None = None,
                 options: AutopilotOptions | None = None) -> None:
        self.sim = Simulation(world, profile, n_vehicles, seed=seed, noise=noise,
                              signing_key=signing_key, options=options)
        self._now_s = self.sim.t_s
        self._vehicle_ports: list[tuple[Channel, MemoryPort]] = []
        self._mocap_ports: list[MemoryPort] = []
        self._truth_ports: list[MemoryPort] = []
        mavlink1 = not profile.mavlink2
        self._mocap = MocapEncoder(mavlink1)
        self._truth = TruthEncoder(mavlink1)
        self.ticks = 0
        # a stalled SITL (`Stall`, or any object with its `resumes_s` and `reached_s`)
        self.stall: Stopping | None = None
        # called with the simulated time after every tick (a fault search's timed faults)
        self.tick_hooks: list[Callable[[float], None]] = []

    @property
    def t_s(self) -> float:
        """The shared clock: simulated seconds (at or after the last vehicle tick)."""
        return self._now_s

    @property
    def mocap_enabled(self) -> bool:
        """Whether the world has motion capture."""
        return bool(self.sim.world.mocap_enabled)

    # ------------------------------------------------------------------ ports
    def vehicle_port(self, sysid: int = 1, faults: PortFaults | None = None) -> MemoryPort:
        """A new link to vehicle `sysid` (SR0_* stream rates, like the TCP endpoint), with
        `faults` on it if given."""
        rt = self.sim.vehicle(sysid)
        ch = rt.add_channel(0, f"memory{len(rt.link.channels)}")
        port = MemoryPort(self, f"vehicle{sysid}/{ch.name}",
                          lambda data: rt.link.receive(ch, data), faults)
        self._vehicle_ports.append((ch, port))
        return port

    def mocap_port(self) -> MemoryPort:
        """A new motion-capture client (ATT_POS_MOCAP of every vehicle); the world must have
        motion capture on."""
        if not self.mocap_enabled:
            raise ValueError("the world has no motion capture")
        port = MemoryPort(self, f"mocap{len(self._mocap_ports)}", None)
        self._mocap_ports.append(port)
        return port

    def truth_port(self) -> MemoryPort:
        """A new ground-truth client (LOCAL_POSITION_NED at 50 Hz, for scoring only)."""
        port = MemoryPort(self, f"truth{len(self._truth_ports)}", None)
        self._truth_ports.append(port)
        return port

    # ------------------------------------------------------------------ time
    def advance_to(self, t_s: float) -> None:
        """Run the vehicles' ticks up to `t_s` (a stalled SITL: up to where it stopped); the
        clock reads `t_s` after (never backwards)."""
        sim = self.sim
        until = t_s if self.stall is None else self.stall.reached_s(t_s)
        while sim.t_s + sim.dt_s <= until + _EPS_S:
            self._tick()
        self._now_s = max(self._now_s, t_s)

    def advance_until(self, done: Callable[[], bool], timeout_s: float) -> None:
        """Tick until `done()` holds (checked before each tick) or `timeout_s` has passed."""
        end = self._now_s + max(0.0, timeout_s)
        sim = self.sim
        stall = self.stall
        while not done():
            due = sim.t_s + sim.dt_s
            if stall is not None:
                # a stopped SITL sends nothing until it wakes, then all it missed at once
                due = max(self._now_s, stall.resumes_s(due))
            if due > end + _EPS_S:
                self._now_s = max(self._now_s, end)
                return
            self.advance_to(due)

    def _tick(self) -> None:
        sim = self.sim
        sim.tick()
        self.ticks += 1
        for hook in self.tick_hooks:
            hook(sim.t_s)
        # what the tick sent leaves at the tick's time (a fade's window is judged on it)
        self._now_s = max(self._now_s, sim.t_s)
        for ch, port in self._vehicle_ports:
            if port.closed:
                ch.discard_output()
            else:
                port.deliver(ch.take())
        frames = sim.take_mocap()
        mocap = [p for p in self._mocap_ports if not p.closed]
        if frames and mocap:
            data = self._mocap.encode(frames)
            for p in mocap:
                p.deliver(data)
        if self._truth.due(sim.t_s):
            truth = [p for p in self._truth_ports if not p.closed]
            if truth:
                data = self._truth.encode(sim.t_s, sim.vehicles)
                for p in truth:
                    p.deliver(data)


def world_of(world: str | Path | Mapping[str, Any] | World | None) -> World:
    """A world from a file, from a world file's table as parsed TOML (a campaign's varied
    copy of one), or as given; None: the empty room. Problems are one-line ValueErrors."""
    if isinstance(world, World):
        return world
    if world is None:
        return default_world()
    if isinstance(world, Mapping):
        try:
            return world_from_toml(dict(world))
        except ParamError as exc:
            raise ValueError(str(exc)) from None
    return load_world(world)


def start(profile: str = "apm25", world: str | Path | Mapping[str, Any] | World | None = None,
          vehicles: int = 1, seed: int = 0, noise: bool = True,
          signing_key: bytes | None = None) -> LockstepSitl:
    """The bundled SITL as `python -m sitl` would start it, but in lockstep: the same world
    (see `world_of`), profile, seed and the world's `[autopilot]` options. A bad world or
    profile is a ValueError of one line."""
    try:
        prof = Profile(profile)
    except ValueError:
        raise ValueError(f"profile {profile!r}: expected one of "
                         f"{', '.join(p.value for p in Profile)}") from None
    loaded = world_of(world)
    if signing_key is not None and not prof.mavlink2:
        raise ValueError("signing needs the copter4 profile (MAVLink 2)")
    return LockstepSitl(loaded, prof, vehicles, seed=seed, noise=noise, signing_key=signing_key,
                        options=loaded.autopilot)
