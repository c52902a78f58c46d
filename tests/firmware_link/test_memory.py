"""`mem:NAME`: an in-memory pipe behind the same transport interface as TCP."""

from __future__ import annotations

import pytest

from firmware_link import memory
from firmware_link.byte_transport import TransportClosed
from firmware_link.connection import Transport, parse_connection_string
from firmware_link.errors import LinkError, LinkUsageError
from firmware_link.transport import open_transport


class Pipe:
    """A far end that echoes what it is sent, and counts how long it was asked to wait."""

    def __init__(self) -> None:
        self.closed = False
        self.buf = bytearray()
        self.waited_s = 0.0
        self.connected = False

    def connect(self) -> None:
        self.connected = True

    def read(self, max_bytes: int) -> bytes:
        if self.closed:
            raise OSError("closed")
        out = bytes(self.buf[:max_bytes])
        del self.buf[:max_bytes]
        return out

    def write(self, data: bytes | memoryview) -> int:
        if self.closed:
            raise OSError("closed")
        self.buf += data
        return len(data)

    def wait_readable(self, timeout_s: float) -> None:
        self.waited_s += timeout_s

    def close(self) -> None:
        self.closed = True


def test_connection_string() -> None:
    spec = parse_connection_string("mem:lockstep1/vehicle1")
    assert spec.transport is Transport.MEMORY and spec.host == "lockstep1/vehicle1"
    assert not spec.reconnectable and spec.capacity_bytes_per_s is None
    with pytest.raises(LinkUsageError, match="expected mem:NAME"):
        parse_connection_string("mem:")


def test_bytes_both_ways_and_waiting_is_the_far_end_s() -> None:
    pipe = Pipe()
    url = memory.plug("test-echo", pipe)
    try:
        assert not pipe.connected
        t = open_transport(parse_connection_string(url))
        assert pipe.connected  # the far end knows a client came, as a TCP accept tells it
        assert t.write(b"\xfe\x09abc") == 5
        t.wait_readable(0.01)
        assert pipe.waited_s == pytest.approx(0.01)
        assert t.read(3) == b"\xfe\x09a" and t.read() == b"bc"
        pipe.close()
        with pytest.raises(TransportClosed, match="mem:test-echo"):
            t.read()
    finally:
        memory.unplug("test-echo")


def test_names_are_unique_and_must_exist() -> None:
    memory.plug("test-once", Pipe())
    try:
        with pytest.raises(LinkError, match="already plugged in"):
            memory.plug("test-once", Pipe())
    finally:
        memory.unplug("test-once")
    with pytest.raises(LinkError, match="mem:test-once: no in-memory port"):
        open_transport(parse_connection_string("mem:test-once"))
