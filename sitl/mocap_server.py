"""The off-board motion-capture system: its own TCP endpoint and MAVLink system id.

Streams ATT_POS_MOCAP for every tracked vehicle as each pose is delivered (100 Hz, with the
world's latency), from system id 200 with component id = the tracked vehicle's system id, so a
station can tell vehicles apart on one connection. Any number of clients may connect; each gets
every pose from the moment it connects. It sends no HEARTBEAT and ignores what clients send
(a station's heartbeat only tells a server where it is). `MocapEncoder` makes the bytes, so the
in-memory lockstep endpoint (`sitl.lockstep`) sends exactly what the socket does.
"""

from __future__ import annotations

from sitl.link.broadcast import BroadcastServer
from sitl.link.codec import MavCodec, messages
from sitl.simulation import MocapFrame

MOCAP_SYSID = 200


class MocapEncoder:
    """ATT_POS_MOCAP frames of delivered poses, one sequence for every listener."""

    def __init__(self, mavlink1: bool) -> None:
        self._codec = MavCodec(MOCAP_SYSID, 1, mavlink1)
        self.sent = 0

    def encode(self, frames: list[MocapFrame]) -> bytes:
        """The frames of `frames`, in order."""
        data = bytearray()
        for f in frames:
            s = f.sample
            self._codec.mav.srcComponent = f.sysid
            msg = messages.MAVLink_att_pos_mocap_message(
                int(s.t_s * 1e6), list(s.q_nb), *s.pos_n, [0.0] * 21
            )
            data += self._codec.encode(msg)
            self.sent += 1
        return bytes(data)


class MocapServer(BroadcastServer):
    """TCP server broadcasting ATT_POS_MOCAP."""

    def __init__(self, port: int, mavlink1: bool, host: str = "127.0.0.1") -> None:
        super().__init__(host, port, "mocap tcp")
        self._encoder = MocapEncoder(mavlink1)

    @property
    def sent(self) -> int:
        """Poses encoded so far."""
        return self._encoder.sent

    def publish(self, frames: list[MocapFrame]) -> None:
        """Encode and queue poses for every client, then send what the sockets take."""
        if not self._clients:
            return
        self._queue_all(self._encoder.encode(frames))
        self._send()
