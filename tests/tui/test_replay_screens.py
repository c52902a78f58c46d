"""The teleop screens on a recorded flight: a real MCAP file, played on an injected clock."""

from __future__ import annotations

import math
from pathlib import Path

from firmware_link.records import Attitude, Heartbeat, Rangefinder, SimTruth, SystemStatus
from gcs import topics
from gcs.pilot import intents
from gcs.tui.app import make_app
from gcs.tui.replay_backend import ReplayBackend
from logs import Recorder, open_recording
from logs.replay import Player


def write_flight(path: Path) -> Path:
    """Ten seconds of a climb to 1 m, at 40 Hz, written by the station's recorder."""
    with Recorder(path, metadata={"profile": "apm25"}, anchor_ns=1_700_000_000_000_000_000) as rec:
        for k in range(400):
            t = 100.0 + 0.025 * k
            alt = min(1.0, 0.1 * k * 0.025 * 4)
            if k % 40 == 0:
                rec.put(topics.HEARTBEAT, t, Heartbeat(t, 1, 1, 0, True, SystemStatus.ACTIVE, 209))
            rec.put(topics.ATTITUDE, t, Attitude(t, 1, 0.01, -0.02, math.pi / 2, 0, 0, 0))
            rec.put(topics.RANGEFINDER, t, Rangefinder(t, 1, alt + 0.01, True, "RANGEFINDER"))
            truth = SimTruth(t, 1, (0, 0, -alt), (0, 0, 0), 0, 0, 0, "SIMSTATE")
            rec.put(topics.SIM_TRUTH, t, truth)
            rec.put(topics.ESTIMATE, t, {"alt_m": alt, "vel_mps": 0.4, "acc_mps2": 0.0})
            rec.put(topics.ALT_CONTROLLER, t, {"setpoint_m": 1.0, "throttle_us": 1490})
            rec.put(topics.RC_OVERRIDE, t, {"roll_us": 1500, "pitch_us": 1500,
                                             "throttle_us": 1490, "yaw_us": 1500})
    return path


async def test_replay_plays_seeks_and_pauses(tmp_path: Path) -> None:
    path = write_flight(tmp_path / "flight.mcap")
    now = [0.0]
    player = Player(open_recording(path), clock=lambda: now[0])
    backend = ReplayBackend(player, name=path.name)
    app = make_app(backend, redraw_timers=False)  # the test drives time and redraws
    async with app.run_test(size=(80, 24)) as pilot:
        now[0] = 5.0
        view = backend.view()
        assert 4.9 < view.t_s <= 5.0
        assert view.vehicle.armed and view.vehicle.mode == "STABILIZE"
        assert view.altitude.setpoint_m == 1.0 and view.altitude.truth_m is not None
        await pilot.press("p")  # pause: time passes, the flight does not
        now[0] = 7.0
        assert backend.view().t_s == view.t_s
        await pilot.press("plus")  # faster
        assert player.speed == 2.0
        await pilot.press("left")  # back 10 s, clamped at the start
        await pilot.press("p")
        now[0] = 7.5
        assert backend.view().t_s <= 1.0
        app.redraw()
        await pilot.pause()
        assert "▶ 2x" in str(app.query_one("#vehicle").render())


async def test_replay_ignores_flying_intents(tmp_path: Path) -> None:
    player = Player(open_recording(write_flight(tmp_path / "f.mcap")), clock=lambda: 0.0)
    backend = ReplayBackend(player)
    backend.send(intents.Arm())
    backend.send(intents.Kill())
    assert backend.view().replay is not None
