"""The teleop TUI's safety rules with Textual's Pilot: LAND ends PC control for good, and
quitting with the vehicle in the air lands it before the station lets go.

The SITL runs as its own program here, so it outlives the station process and the landing
after a quit can be watched on motion capture and a listen-only UDP endpoint.
"""

from __future__ import annotations

import socket
import time
from pathlib import Path

import numpy as np
import pytest

from gcs.station.session import SessionOptions
from gcs.tui.app import make_app
from gcs.tui.help import ConfirmQuit
from gcs.tui.process_backend import ProcessBackend
from tests.e2e.fault_flight import _sitl
from tests.e2e.fault_watch import MavWatcher
from tests.e2e.test_teleop_tui import truth_alt, wait_until

pytestmark = [pytest.mark.e2e, pytest.mark.timeout(240)]


async def _climb(pilot, backend: ProcessBackend, steps: int = 5) -> None:  # type: ignore[no-untyped-def]
    await pilot.press("a")
    await wait_until(pilot, backend, lambda v: v.vehicle.armed, 20.0)
    await pilot.press("h")
    await wait_until(pilot, backend, lambda v: v.altitude.hold_on, 5.0)
    for _ in range(steps):
        await pilot.press("plus")
    await wait_until(pilot, backend, lambda v: truth_alt(v) > 0.45, 30.0)


async def test_land_ends_hold_and_stabilize_keeps_the_throttle_down(tmp_path: Path) -> None:
    backend = ProcessBackend(SessionOptions(command="teleop", seed=7, output=tmp_path))
    app = make_app(backend)
    async with app.run_test(size=(80, 24)) as pilot:
        await _climb(pilot, backend)
        await pilot.press("l")
        view = await wait_until(pilot, backend, lambda v: v.vehicle.mode == "LAND", 5.0)
        view = await wait_until(pilot, backend, lambda v: not v.altitude.hold_on, 2.0)
        await wait_until(pilot, backend, lambda v: v.altitude.throttle_us == 1000, 2.0)
        top = truth_alt(view)
        await pilot.press("1")  # back to STABILIZE while coming down: no relaunch
        await wait_until(pilot, backend, lambda v: v.vehicle.mode == "STABILIZE", 5.0)
        highest = top
        deadline = time.monotonic() + 4.0
        while time.monotonic() < deadline:
            v = backend.view()
            highest = max(highest, truth_alt(v))
            assert v.altitude.throttle_us == 1000 and not v.altitude.hold_on
            await pilot.pause(0.1)
        assert highest <= top + 0.05
        assert any("PC control off" in text for _, text in backend.view().messages)
        await pilot.press("space")
        await wait_until(pilot, backend, lambda v: not v.vehicle.armed, 20.0)
    assert backend.error is None


async def test_quit_mid_air_asks_then_lands_before_letting_go(tmp_path: Path) -> None:
    udp = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    udp.bind(("127.0.0.1", 0))
    with _sitl(["--tcp", "0", "--seed", "6", "--udp",
                f"127.0.0.1:{udp.getsockname()[1]}"]) as sitl:
        watch = MavWatcher(udp, udp=True)
        mocap_url = next(line.split(" ", 1)[1] for line in sitl.lines if line.startswith("mocap "))
        host, port = mocap_url.removeprefix("tcp:").rsplit(":", 1)
        mocap = MavWatcher(socket.create_connection((host, int(port)), 5.0), udp=False)
        try:
            backend = ProcessBackend(SessionOptions(
                command="teleop", connect="tcp:" + sitl.endpoint(1, "tcp"), mocap=mocap_url,
                output=tmp_path))
            app = make_app(backend)
            async with app.run_test(size=(80, 24)) as pilot:
                await _climb(pilot, backend)
                await pilot.press("ctrl+q")
                await pilot.pause(0.2)
                assert isinstance(app.screen, ConfirmQuit)  # armed: it asks first
                await pilot.press("n")
                await pilot.pause(0.2)
                assert not isinstance(app.screen, ConfirmQuit) and backend.view().vehicle.armed
                await pilot.press("ctrl+q")
                await pilot.pause(0.2)
                quit_at = time.monotonic()
                await pilot.press("y")
            # the app is gone and its station process has ended: the vehicle must be landing
            watch.wait_until(lambda m: any(w > quit_at and not armed
                                           for w, armed, _ in m.heartbeats),
                             quit_at + 25.0 - time.monotonic())
            modes = [mode for w, _, mode in watch.heartbeats if w > quit_at]
            assert 9 in modes, f"never in LAND after the quit: {modes}"
            assert any(w > quit_at and not armed for w, armed, _ in watch.heartbeats)
            track = np.array([(w, h) for w, _, h in mocap.mocap if w > quit_at])
            floor = min(h for _, _, h in mocap.mocap[:50])
            assert track[:, 1].max() - floor < 1.0  # no climb on the way out
            assert track[-1, 1] - floor < 0.05  # on the floor
        finally:
            mocap.close()
            watch.close()
