"""The SITL's MAVLink side: codec, per-link channels and stream rates, the autopilot's message
handling, telemetry builders and socket/pty endpoints. The real-time loop that runs a
Simulation behind them is `sitl.link.server.SitlServer` (not imported here: it needs the
simulation, which needs this package)."""

from sitl.link.channel import COMPANION_COMPID, Channel
from sitl.link.codec import MavCodec
from sitl.link.endpoints import (
    EndpointError,
    PtySerialEndpoint,
    TcpServerEndpoint,
    UdpEndpoint,
)
from sitl.link.handler import VehicleLink
from sitl.link.streams import Stream, StreamSchedule
from sitl.link.view import GeoOrigin, SensorCache, VehicleView

__all__ = [
    "COMPANION_COMPID",
    "Channel",
    "EndpointError",
    "GeoOrigin",
    "MavCodec",
    "PtySerialEndpoint",
    "SensorCache",
    "Stream",
    "StreamSchedule",
    "TcpServerEndpoint",
    "UdpEndpoint",
    "VehicleLink",
    "VehicleView",
]
