"""In-memory byte pipes: the `mem:NAME` connection string, for a simulator in this process.

A lockstep flight runs the station and the bundled simulator in one process on one simulated
clock. The simulator's ports are plugged in here under a name; `VehicleLink.open("mem:NAME")`
(and `MocapLink`, `TruthLink`) then speak to them through `MemoryTransport` with the same
framing, parsing, queueing and watchdog as over TCP. Waiting for bytes on a pipe is the
simulator letting its time pass (`BytePipe.wait_readable`), so the link's blocking helpers
(bring-up, parameters, arming) need no wall clock either.

The names live in this process, as ports on a loopback interface do on a machine: plugging a
name twice is an error, and `unplug` frees it.
"""

from __future__ import annotations

from typing import Protocol

from firmware_link.byte_transport import READ_BUDGET_BYTES, TransportClosed
from firmware_link.connection import ConnectionSpec
from firmware_link.errors import LinkError

SCHEME = "mem"


class BytePipe(Protocol):
    """The far end of an in-memory link (e.g. `sitl.lockstep.MemoryPort`)."""

    closed: bool

    def connect(self) -> None: ...  # a client opened it, as a TCP accept: send from now on
    def read(self, max_bytes: int) -> bytes: ...
    def write(self, data: bytes | memoryview) -> int: ...
    def wait_readable(self, timeout_s: float) -> None: ...
    def close(self) -> None: ...


_pipes: dict[str, BytePipe] = {}


def plug(name: str, pipe: BytePipe) -> str:
    """Make `pipe` reachable as `mem:<name>`; returns that connection string."""
    if not name or any(ch.isspace() for ch in name):
        raise LinkError(f"in-memory port name {name!r}: expected a non-empty name without spaces")
    if name in _pipes:
        raise LinkError(f"{SCHEME}:{name}: an in-memory port of that name is already plugged in")
    _pipes[name] = pipe
    return f"{SCHEME}:{name}"


def unplug(name: str) -> None:
    """Forget the name (idempotent); links already open keep their pipe."""
    _pipes.pop(name, None)


class MemoryTransport:
    """A `ByteTransport` over a `BytePipe`: never blocks, never fills."""

    def __init__(self, spec: ConnectionSpec, pipe: BytePipe) -> None:
        self.spec = spec
        self._pipe = pipe

    @classmethod
    def open(cls, spec: ConnectionSpec) -> MemoryTransport:
        """The pipe plugged in under the connection string's name; LinkError if none is."""
        pipe = _pipes.get(spec.host)
        if pipe is None or pipe.closed:
            raise LinkError(f"{spec.url}: no in-memory port of that name in this process")
        pipe.connect()
        return cls(spec, pipe)

    def read(self, max_bytes: int = READ_BUDGET_BYTES) -> bytes:
        """What waits, up to `max_bytes`; TransportClosed once the far end closed."""
        try:
            return self._pipe.read(max_bytes)
        except OSError as exc:
            raise TransportClosed(f"{self.spec.url}: {exc}") from None

    def write(self, data: bytes | memoryview) -> int:
        """Hand all of `data` to the far end; TransportClosed once it closed."""
        try:
            return self._pipe.write(data)
        except OSError as exc:
            raise TransportClosed(f"{self.spec.url}: {exc}") from None

    def wait_readable(self, timeout_s: float) -> None:
        """Let the far end's time pass until bytes wait or `timeout_s` passes."""
        self._pipe.wait_readable(timeout_s)

    def wait_writable(self, timeout_s: float) -> None:
        """A pipe always takes bytes."""

    @property
    def has_peer(self) -> bool:
        """A plugged-in pipe always has its far end."""
        return True

    def fileno(self) -> int:
        """No descriptor: nothing to select on."""
        return -1

    def close(self) -> None:
        """Close the pipe."""
        self._pipe.close()
