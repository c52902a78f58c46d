"""A minimal ground station for SITL tests: a pymavlink MAVLink object over an in-memory link."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from pymavlink.dialects.v20 import ardupilotmega as mavlink

from sitl.simulation import MemoryLink, Simulation


class _Sink:
    def __init__(self) -> None:
        self.data = bytearray()

    def write(self, b: bytes) -> None:
        self.data += b


class MemoryGcs:
    """Sends as system 255 (or `sysid`) and collects everything the vehicle sends."""

    def __init__(self, sim: Simulation, link: MemoryLink, mavlink1: bool, sysid: int = 255) -> None:
        self.sim = sim
        self.link = link
        self._sink = _Sink()
        self.mav = mavlink.MAVLink(self._sink, srcSystem=sysid, srcComponent=190)
        self.mav.robust_parsing = True
        self.mavlink1 = mavlink1
        self.received: list[Any] = []

    def send(self, msg: Any) -> None:
        """Encode and deliver one message."""
        self.mav.send(msg, force_mavlink1=self.mavlink1)
        self.link.write(bytes(self._sink.data))
        self._sink.data.clear()

    def send_raw(self, data: bytes) -> None:
        """Deliver arbitrary bytes."""
        self.link.write(data)

    def poll(self) -> list[Any]:
        """Decode what the vehicle sent since the last poll."""
        msgs = [m for m in (self.mav.parse_buffer(self.link.read()) or []) if m is not None]
        self.received.extend(msgs)
        return msgs

    def run(self, seconds: float, every_tick: Callable[[], None] | None = None) -> list[Any]:
        """Advance the simulation, calling `every_tick` before each tick; return messages."""
        out: list[Any] = []
        end = self.sim.t_s + seconds
        while self.sim.t_s + 1e-9 < end:
            if every_tick is not None:
                every_tick()
            self.sim.tick()
            out.extend(self.poll())
        return out

    def heartbeat(self) -> None:
        """A GCS heartbeat."""
        self.send(mavlink.MAVLink_heartbeat_message(6, 8, 0, 0, 0, 3))

    def override(self, target: int, *channels: int) -> None:
        """RC_CHANNELS_OVERRIDE of channels 1..8 (missing ones 0 = released)."""
        ch = list(channels) + [0] * (8 - len(channels))
        if self.mavlink1:
            self.send(mavlink.MAVLink_rc_channels_override_message(target, 1, *ch))
        else:
            self.send(mavlink.MAVLink_rc_channels_override_message(target, 1, *ch, *([65535] * 10)))

    def command(self, target: int, command: int, *params: float) -> None:
        """COMMAND_LONG with up to seven parameters."""
        p = list(params) + [0.0] * (7 - len(params))
        self.send(mavlink.MAVLink_command_long_message(target, 1, command, 0, *p))

    def set_mode(self, target: int, mode: int) -> None:
        """SET_MODE with a custom mode."""
        self.send(mavlink.MAVLink_set_mode_message(target, 1, mode))

    def of_type(self, kind: str, msgs: list[Any] | None = None) -> list[Any]:
        """Messages of one type (from `msgs`, or everything received)."""
        return [m for m in (self.received if msgs is None else msgs) if m.get_type() == kind]
