"""The station's live checks: what the pilot is told while flying, and the flight's summary."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from firmware_link.records import Imu
from firmware_link.stats import LinkStats
from gcs.station.live_check import LiveCheck
from gcs.station.loop import TickTiming
from logs import open_recording
from logs.check import Status

PERIOD_S = 0.025


def _timing(k: int, overrun: bool) -> TickTiming:
    return TickTiming(k, k * PERIOD_S, k * PERIOD_S, PERIOD_S, 0.0, 0.0, 0.001, overrun)


def _fly(check: LiveCheck, seconds: float, *, loss: float = 0.0, overrun_every: int = 0,
         vibration_mps2: float = 0.3, seed: int = 1) -> list[tuple[float, str]]:
    """Tick for `seconds` with 400 frames a second (a share `loss` lost), an IMU at 20 Hz."""
    rng = np.random.default_rng(seed)
    told: list[tuple[float, str]] = []
    for k in range(int(seconds / PERIOD_S)):
        t = k * PERIOD_S
        sent = 10 * (k + 1)
        lost = round(sent * loss)
        rx = sent - lost
        if k % 2 == 0:
            acc = rng.normal(0.0, vibration_mps2, 3) + np.array([0.0, 0.0, -9.81])
            check.imu(Imu(t, 1, (float(acc[0]), float(acc[1]), float(acc[2])), (0.0,) * 3,
                          "RAW_IMU"))
        over = bool(overrun_every) and k % overrun_every == 0
        for text in check.tick(t, True, LinkStats(rx_messages=rx, lost_messages=lost),
                               _timing(k, over)):
            told.append((t, text))
    return told


def test_a_clean_flight_tells_nothing_and_sums_up_pass() -> None:
    check = LiveCheck()
    assert _fly(check, 60.0) == []
    status, line = check.summary()
    assert status is Status.PASS and line.startswith("live checks PASS")
    assert "0 overruns in 2400 ticks" in line


def test_link_loss_is_told_over_ten_seconds_and_not_every_tick() -> None:
    check = LiveCheck()
    told = _fly(check, 60.0, loss=0.12)
    texts = [text for _t, text in told if text.startswith("link loss")]
    assert texts and texts[0] == "link loss 12 % over 10 s"
    assert len(texts) == 2  # told, then again 30 s later while it lasts
    status, line = check.summary()
    assert status is Status.FAIL and "link loss worst 12.0 %" in line


def test_overruns_and_vibration_are_told() -> None:
    check = LiveCheck()
    told = _fly(check, 20.0, overrun_every=20, vibration_mps2=2.5)
    texts = " / ".join(text for _t, text in told)
    assert "loop overruns: 20 of 400 ticks in the last 10 s" in texts
    assert "vibration high" in texts
    status, line = check.summary()
    assert status is Status.FAIL
    rms = float(line.split("vibration ")[1].split(" ")[0])
    assert math.isclose(rms, 2.5, rel_tol=0.15)


def test_vibration_on_the_floor_does_not_count() -> None:
    check = LiveCheck()
    rng = np.random.default_rng(2)
    for k in range(2000):
        t = k * PERIOD_S
        acc = rng.normal(0.0, 5.0, 3)
        check.imu(Imu(t, 1, (float(acc[0]), float(acc[1]), float(acc[2])), (0.0,) * 3, "x"))
        assert check.tick(t, False, LinkStats(rx_messages=k), None) == []
    assert check.summary()[0] is Status.PASS


def test_a_fault_in_it_is_told_once_and_never_raises() -> None:
    check = LiveCheck()
    bad: Any = None  # stats that are not LinkStats: a bug, as the loop would meet it
    told = [text for k in range(100) for text in check.tick(k * PERIOD_S, True, bad, None)]
    assert len(told) == 1 and told[0].startswith("live check failed")
    assert check.faults == 100


def test_a_vibrating_imu_is_told_in_flight_and_summed_up(tmp_path: Path) -> None:
    """In the recording's events, and in the messages the TUI shows (its station backend)."""
    from gcs.tui.station_backend import StationBackend
    from tests.logs.check_flights import fly_recorded

    backends: list[StationBackend] = []

    def watch(session: Any) -> None:
        backends.append(StationBackend(session.first.station))

    path, summary = fly_recorded(tmp_path / "vibe.mcap", hold_s=5.0, during=watch,
                                 world={"sensors": {"imu": {"acc_vibration_mps2_full": 6.0}}})
    events = [m["text"] for _t, _ns, m in open_recording(path).messages(["/gcs/events"])]
    assert any(text.startswith("vibration high") for text in events), events
    assert not any(text.startswith("link loss") for text in events)
    shown = [text for _t, text in backends[0].view().messages]
    assert any(text.startswith("vibration high") for text in shown), shown
    if summary["status"] == "ok":
        assert summary["live_checks"].startswith("live checks FAIL")
