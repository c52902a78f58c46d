"""`open_when_up`: waiting for a vehicle that is not up yet, over real sockets with short
deadlines (the TCP case with a real SITL is in tests/e2e/test_fly_cli.py)."""

from __future__ import annotations

import socket
import threading

import pytest

from firmware_link import LinkError, LinkUsageError, open_when_up


def test_udp_waits_for_a_heartbeat_says_so_and_ends_with_one_line() -> None:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    url = f"udpin:127.0.0.1:{port}"
    lines: list[str] = []
    with pytest.raises(LinkError) as err:
        open_when_up(url, timeout_s=1.5, on_wait=lines.append)
    assert len(lines) == 1 and lines[0].startswith(f"waiting for a vehicle heartbeat on {url}")
    text = str(err.value)
    assert text.startswith(f"{url}: no vehicle within 1.5 s (no vehicle heartbeat"), text
    assert "nothing received" in text and "--connect-timeout" in text and "\n" not in text


def test_a_peer_that_hangs_up_before_a_heartbeat_is_tried_again() -> None:
    server = socket.socket()
    server.bind(("127.0.0.1", 0))
    server.listen()
    accepted: list[int] = []
    stop = threading.Event()

    def hang_up() -> None:
        server.settimeout(0.1)
        while not stop.is_set():
            try:
                conn, _ = server.accept()
            except TimeoutError:
                continue
            accepted.append(1)
            conn.close()

    worker = threading.Thread(target=hang_up, daemon=True)
    worker.start()
    url = f"tcp:127.0.0.1:{server.getsockname()[1]}"
    lines: list[str] = []
    try:
        with pytest.raises(LinkError) as err:
            open_when_up(url, timeout_s=2.0, on_wait=lines.append)
    finally:
        stop.set()
        worker.join()
        server.close()
    assert len(accepted) >= 3  # tried again every half second until the deadline
    assert lines[0].startswith(f"waiting for the vehicle on {url} (the peer closed the link")
    assert "no vehicle within 2 s (the peer closed the link before a vehicle heartbeat)" in str(
        err.value)


def test_what_waiting_cannot_cure_ends_at_once() -> None:
    with pytest.raises(LinkUsageError):
        open_when_up("bogus::url", timeout_s=30.0)
    with pytest.raises(LinkError, match="cannot connect") as err:
        open_when_up("tcp:no-such-host.invalid:5760", timeout_s=30.0)
    assert "no vehicle within" not in str(err.value)  # not waited for
