"""Connection strings as pymavlink and other ground stations write them, validated up front.

Accepted forms:
    /dev/ttyUSB0            serial device at 115200 baud
    /dev/ttyUSB0,57600      serial device at the given baud
    udpin:0.0.0.0:14550     listen for the vehicle on a local UDP port
    udpout:HOST:PORT        send to the vehicle's UDP port
    tcp:HOST:PORT           connect to the vehicle's TCP port
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

from firmware_link.errors import LinkUsageError

DEFAULT_BAUD = 115200
STANDARD_BAUDS: frozenset[int] = frozenset(
    {9600, 19200, 38400, 57600, 111100, 115200, 230400, 250000, 460800, 500000, 921600, 1500000}
)
# 8N1 framing spends 10 bit times per byte on the wire.
BITS_PER_SERIAL_BYTE = 10

EXPECTED_FORMS = "expected /dev/PORT[,BAUD], udpin:HOST:PORT, udpout:HOST:PORT or tcp:HOST:PORT"


class Transport(enum.Enum):
    """How the bytes travel."""

    SERIAL = "serial"
    UDPIN = "udpin"
    UDPOUT = "udpout"
    TCP = "tcp"
    MEMORY = "mem"  # an in-memory pipe to a simulator in this process (firmware_link.memory)


@dataclass(frozen=True, slots=True)
class ConnectionSpec:
    """A validated connection string."""

    url: str
    transport: Transport
    host: str = ""
    port: int = 0
    device: str = ""
    baud: int = DEFAULT_BAUD

    @property
    def capacity_bytes_per_s(self) -> float | None:
        """Bytes per second the medium carries; None for network links (not the bottleneck)."""
        if self.transport is Transport.SERIAL:
            return self.baud / BITS_PER_SERIAL_BYTE
        return None

    @property
    def reconnectable(self) -> bool:
        """TCP and serial links can be reopened after the peer vanished; UDP needs no reopen."""
        return self.transport in (Transport.TCP, Transport.SERIAL)


def _parse_host_port(url: str, rest: str) -> tuple[str, int]:
    host, sep, port_text = rest.rpartition(":")
    if not sep or not host:
        raise LinkUsageError(f"connection string {url!r}: missing HOST:PORT; {EXPECTED_FORMS}")
    if not port_text.isdigit():
        raise LinkUsageError(f"connection string {url!r}: port {port_text!r} is not a number")
    port = int(port_text)
    if not 0 <= port <= 65535:
        raise LinkUsageError(f"connection string {url!r}: port {port} is outside 0..65535")
    if any(ch.isspace() for ch in host):
        raise LinkUsageError(f"connection string {url!r}: host {host!r} contains spaces")
    return host, port


def parse_connection_string(url: str) -> ConnectionSpec:
    """Validate `url` and split it into its parts; raise LinkUsageError naming what is wrong."""
    text = url.strip()
    if not text:
        raise LinkUsageError(f"connection string is empty; {EXPECTED_FORMS}")
    scheme, sep, rest = text.partition(":")
    if sep and scheme in ("udpin", "udpout", "tcp"):
        host, port = _parse_host_port(url, rest)
        transport = Transport(scheme)
        if port == 0 and transport is not Transport.UDPIN:
            raise LinkUsageError(f"connection string {url!r}: port 0 cannot be connected to")
        return ConnectionSpec(url=text, transport=transport, host=host, port=port)
    if sep and scheme == Transport.MEMORY.value:
        if not rest or any(ch.isspace() for ch in rest):
            raise LinkUsageError(f"connection string {url!r}: expected mem:NAME of an in-memory "
                                 "port (a lockstep simulator in this process)")
        return ConnectionSpec(url=text, transport=Transport.MEMORY, host=rest)
    if text.startswith("/") or text.upper().startswith("COM"):
        device, comma, baud_text = text.partition(",")
        baud = DEFAULT_BAUD
        if comma:
            if not baud_text.isdigit():
                raise LinkUsageError(
                    f"connection string {url!r}: baud {baud_text!r} is not a number"
                )
            baud = int(baud_text)
            if baud not in STANDARD_BAUDS:
                raise LinkUsageError(
                    f"connection string {url!r}: baud {baud} is not one of "
                    f"{', '.join(str(b) for b in sorted(STANDARD_BAUDS))}"
                )
        if not device or device.endswith("/"):
            raise LinkUsageError(f"connection string {url!r}: no serial device; {EXPECTED_FORMS}")
        return ConnectionSpec(url=text, transport=Transport.SERIAL, device=device, baud=baud)
    raise LinkUsageError(f"connection string {url!r} not understood; {EXPECTED_FORMS}")
