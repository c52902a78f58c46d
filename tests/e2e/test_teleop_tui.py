"""The teleop TUI flies the bundled SITL: Textual's Pilot presses the pilot's keys.

The station runs in its own process, exactly as `quadgcs teleop` runs it; the test sees only
what the pilot sees, the views the station process sends.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path

import pytest

from gcs.pilot.view import TeleopView
from gcs.station.session import SessionOptions
from gcs.tui.app import make_app
from gcs.tui.process_backend import ProcessBackend

pytestmark = pytest.mark.e2e


async def wait_until(pilot, backend: ProcessBackend,  # type: ignore[no-untyped-def]
                     cond: Callable[[TeleopView], bool], timeout_s: float) -> TeleopView:
    """Let the app run until the latest view satisfies `cond` (or fail at the deadline)."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        view = backend.view()
        if cond(view):
            return view
        await pilot.pause(0.1)
    raise AssertionError(f"condition not met within {timeout_s} s; last view: {backend.view()}")


def truth_alt(v: TeleopView) -> float:
    return v.altitude.truth_m if v.altitude.truth_m is not None else float("nan")


async def test_pilot_arms_holds_climbs_and_kills(tmp_path: Path) -> None:
    backend = ProcessBackend(SessionOptions(command="teleop", seed=7, output=tmp_path))
    app = make_app(backend)
    async with app.run_test(size=(80, 24)) as pilot:
        await pilot.press("a")
        await wait_until(pilot, backend, lambda v: v.vehicle.armed, 15.0)
        await pilot.press("h")
        await wait_until(pilot, backend, lambda v: v.altitude.hold_on, 5.0)
        for _ in range(6):  # six 0.1 m steps from the floor's ~0.06 m
            await pilot.press("plus")
        view = await wait_until(pilot, backend, lambda v: truth_alt(v) > 0.55, 20.0)
        assert view.vehicle.armed and view.altitude.setpoint_m is not None
        app.redraw()
        await pilot.pause()
        assert "hold ON" in str(app.query_one("#altitude").render())
        await pilot.press("space")
        await wait_until(pilot, backend, lambda v: not v.vehicle.armed, 10.0)
        await pilot.press("d")
        await wait_until(pilot, backend, lambda v: truth_alt(v) < 0.15, 10.0)
        assert any("KILL" in text for _, text in backend.view().messages)
    # leaving the app closed the backend: the station process released overrides and ended
    assert backend.error is None
    assert any(tmp_path.glob("*.mcap"))
