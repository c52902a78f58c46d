"""The fixed-rate loop on a simulated clock: period, no drift, overruns counted and skipped."""

from __future__ import annotations

import pytest

from gcs.clock import MonotonicClock, SimClock
from gcs.station.loop import FixedRateLoop


def test_ticks_start_on_absolute_deadlines_without_drift() -> None:
    clock = SimClock(100.0)
    starts: list[float] = []

    def tick(k: int, t_s: float, dt_s: float) -> None:
        starts.append(t_s)
        clock.advance(0.003)  # compute time

    loop = FixedRateLoop(clock, 0.025, tick)
    loop.run(max_ticks=4000)
    assert starts[-1] == pytest.approx(100.0 + 3999 * 0.025, abs=1e-9)
    stats = loop.stats()
    assert stats.ticks == 4000
    assert stats.overruns == 0
    assert stats.period_mean_s == pytest.approx(0.025, abs=1e-9)
    assert stats.jitter_p99_s < 1e-9
    assert stats.compute_p50_s == pytest.approx(0.003, abs=1e-9)


def test_overrun_is_counted_and_loop_skips_ahead() -> None:
    clock = SimClock(0.0)
    starts: list[float] = []

    def tick(k: int, t_s: float, dt_s: float) -> None:
        starts.append(t_s)
        clock.advance(0.060 if k == 3 else 0.001)  # tick 3 takes 2.4 periods

    loop = FixedRateLoop(clock, 0.025, tick)
    loop.run(max_ticks=8)
    stats = loop.stats()
    assert stats.overruns == 1
    assert stats.missed_deadlines == 2  # deadlines 0.100 and 0.125 passed during tick 3
    # after the overrun the loop is back on the original grid, not shifted
    assert starts[4] == pytest.approx(0.150)
    assert starts[5] == pytest.approx(0.175)
    assert loop.last_timing is not None and not loop.last_timing.overrun


def test_stop_from_tick_ends_the_loop() -> None:
    clock = SimClock()
    loop: FixedRateLoop

    def tick(k: int, t_s: float, dt_s: float) -> None:
        if k == 9:
            loop.stop()

    loop = FixedRateLoop(clock, 0.01, tick)
    loop.run()
    assert loop.stats().ticks == 10


def test_monotonic_clock_sleep_until_is_not_early() -> None:
    clock = MonotonicClock()
    target = clock.now_s() + 0.01
    clock.sleep_until(target)
    assert clock.now_s() >= target


def test_bad_period_rejected() -> None:
    with pytest.raises(ValueError, match="period_s"):
        FixedRateLoop(SimClock(), 0.0, lambda k, t, dt: None)
