"""The teleop TUI flies the bundled SITL: Textual's Pilot presses the pilot's keys."""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path

import pytest

from gcs.commands.teleop import TUI_SPIN_S
from gcs.session import SessionOptions, StationSession
from gcs.station import StationSnapshot
from gcs.tui.app import make_app
from gcs.tui.station_backend import StationBackend

pytestmark = pytest.mark.e2e


async def wait_until(pilot, station, cond: Callable[[StationSnapshot], bool],  # type: ignore[no-untyped-def]
                     timeout_s: float) -> StationSnapshot:
    """Let the app run until the station's snapshot satisfies `cond` (or fail at the deadline)."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        snap = station.snapshot()
        if cond(snap):
            return snap
        await pilot.pause(0.1)
    raise AssertionError(f"condition not met within {timeout_s} s; last: {station.snapshot()}")


def truth_alt(s: StationSnapshot) -> float:
    return -s.truth.pos_n[2] if s.truth is not None else float("nan")


async def test_pilot_arms_holds_climbs_and_kills(tmp_path: Path) -> None:
    options = SessionOptions(command="teleop", seed=7, output=tmp_path, spin_s=TUI_SPIN_S)
    with StationSession(options) as session:
        v = session.first
        backend = StationBackend(v.station, url=v.url, recording=str(v.recorder.path),
                                 dialect=v.link.dialect.value)
        v.station.start()
        app = make_app(backend)
        async with app.run_test(size=(80, 24)) as pilot:
            await pilot.press("a")
            await wait_until(pilot, v.station, lambda s: s.armed, 15.0)
            await pilot.press("h")
            await wait_until(pilot, v.station, lambda s: s.alt_setpoint_m is not None, 5.0)
            for _ in range(6):  # six 0.1 m steps from the floor's ~0.06 m
                await pilot.press("plus")
            snap = await wait_until(pilot, v.station, lambda s: truth_alt(s) > 0.55, 20.0)
            assert snap.armed
            # the screen shows the hold and an altitude that followed the setpoint
            app.redraw()
            await pilot.pause()
            altitude = str(app.query_one("#altitude").render())
            assert "hold ON" in altitude
            await pilot.press("space")
            await wait_until(pilot, v.station, lambda s: not s.armed, 10.0)
            await pilot.press("d")
            await wait_until(pilot, v.station, lambda s: truth_alt(s) < 0.15, 10.0)
        assert not v.station.running  # closing the app stopped the loop (overrides released)
    assert any(tmp_path.glob("*.mcap"))
