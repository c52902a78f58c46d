"""The teleop screen names the firmware and how it was identified (the bundled copter4 SITL
answers AUTOPILOT_VERSION as 4.x does), in the link panel the pilot reads."""

from __future__ import annotations

import time
from pathlib import Path

import pytest

from gcs.station.session import SessionOptions
from gcs.tui.app import make_app
from gcs.tui.process_backend import ProcessBackend

pytestmark = pytest.mark.e2e


async def test_link_panel_names_the_firmware(tmp_path: Path) -> None:
    backend = ProcessBackend(SessionOptions(command="teleop", profile="copter4", seed=3,
                                            record=False, output=tmp_path))
    app = make_app(backend)
    async with app.run_test(size=(120, 40)) as pilot:
        deadline = time.monotonic() + 30.0
        while not backend.view().link.connected and time.monotonic() < deadline:
            await pilot.pause(0.1)
        link = backend.view().link
        assert (link.firmware, link.firmware_source) == (
            "ArduCopter V4.7.0-dev", "AUTOPILOT_VERSION"), link
        app.redraw()
        await pilot.pause()
        shown = str(app.query_one("#link").render())
        assert "ArduCopter V4.7.0-dev" in shown and "AUTOPILOT_VERSION" in shown, shown
    assert backend.error is None
