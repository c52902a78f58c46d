"""What the link needs of a transport, whatever its medium (`transport`: sockets and serial;
`memory`: an in-process simulator's pipes), and how a transport says its peer is gone."""

from __future__ import annotations

from typing import Protocol

from firmware_link.errors import LinkError

# One poll() parses at most this much (≈ 10 ms of pymavlink work); a backlog after a stall is
# worked off over the next ticks instead of stalling one of them.
READ_BUDGET_BYTES = 16384


class TransportClosed(LinkError):
    """The peer went away (TCP EOF, serial device gone)."""


class ByteTransport(Protocol):
    """What the link needs from a transport."""

    def read(self, max_bytes: int = READ_BUDGET_BYTES) -> bytes: ...
    def write(self, data: bytes | memoryview) -> int: ...
    def wait_readable(self, timeout_s: float) -> None: ...
    def wait_writable(self, timeout_s: float) -> None: ...
    @property
    def has_peer(self) -> bool: ...
    def close(self) -> None: ...
    def fileno(self) -> int: ...
