"""Waiting for a vehicle that is not up yet, as MAVProxy and QGroundControl do.

A pilot often starts the ground station before the vehicle (or its simulator) is powered: a
TCP port that refuses, a serial device not plugged in yet, a UDP port with no heartbeat yet.
`open_when_up` keeps trying until a deadline, telling the pilot it waits, and ends with one
line naming the address and the last reason when the deadline passes. Errors that waiting
cannot cure (a bad connection string, a busy serial port, a misspelt host) end at once.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

from firmware_link.errors import LinkError, VehicleNotUp
from firmware_link.vehicle_link import VehicleLink

DEFAULT_CONNECT_TIMEOUT_S = 30.0
RETRY_S = 0.5  # between connection attempts: a SITL's port opens within this of starting
NOTICE_EVERY_S = 5.0  # a "still waiting" line this often
MIN_HEARTBEAT_WAIT_S = 0.5  # a connection accepted late still gets this long for a heartbeat


def _reason(url: str, exc: LinkError) -> str:
    """The error's text without the address the final line already names."""
    return str(exc).removeprefix(f"{url}: ")


def open_when_up(
    url: str,
    *,
    timeout_s: float = DEFAULT_CONNECT_TIMEOUT_S,
    on_wait: Callable[[str], None] | None = None,
    clock: Callable[[], float] = time.monotonic,
    sleep: Callable[[float], None] = time.sleep,
    **open_kwargs: Any,
) -> VehicleLink:
    """`VehicleLink.open(url, ...)`, retried while nothing answers, for up to `timeout_s`.

    `on_wait` gets a line when the wait starts and every `NOTICE_EVERY_S` after; the link's
    own heartbeat wait uses what is left of the deadline. LinkError (exit 1) naming `url`
    and the last reason when the deadline passes.
    """
    if not timeout_s > 0:
        raise ValueError(f"timeout_s {timeout_s}: expected > 0")
    start = clock()
    deadline = start + timeout_s
    next_notice = start
    told = False

    def heard(line: str) -> None:
        nonlocal told
        told = True
        if on_wait is not None:
            on_wait(line)

    while True:
        left = max(deadline - clock(), MIN_HEARTBEAT_WAIT_S)
        try:
            return VehicleLink.open(url, wait_heartbeat_s=left, clock=clock,
                                    on_wait=None if told else heard, **open_kwargs)
        except VehicleNotUp as exc:
            last = exc
        now = clock()
        if now + RETRY_S >= deadline:
            raise LinkError(
                f"{url}: no vehicle within {timeout_s:g} s ({_reason(url, last)}); is it on "
                "and at this address? (--connect-timeout S waits longer)"
            ) from None
        if now >= next_notice:
            waited = now - start
            if told:
                heard(f"still waiting for the vehicle on {url}: {waited:.0f} s of {timeout_s:g} "
                      f"({_reason(url, last)})")
            else:
                heard(f"waiting for the vehicle on {url} ({_reason(url, last)}); "
                      f"giving up in {timeout_s:g} s")
            next_notice = now + NOTICE_EVERY_S
        sleep(RETRY_S)
