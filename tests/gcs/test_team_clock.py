"""A mission's waits in lockstep fly every vehicle's station: ticks run earliest first on the
shared simulated time, which never goes back, and a station whose tick raised drops out."""

from __future__ import annotations

import pytest

from gcs.lockstep import LockstepClock, TeamClock
from gcs.station.loop import FixedRateLoop


class Timeline:
    """A simulation's time: it refuses to run backwards."""

    def __init__(self) -> None:
        self.t_s = 0.0

    def advance_to(self, t_s: float) -> None:
        assert t_s >= self.t_s - 1e-12, f"time ran back from {self.t_s} to {t_s}"
        self.t_s = max(self.t_s, t_s)


class Stepped:
    """A station run by run_tick: a real fixed-rate loop on the lockstep clock."""

    def __init__(self, name: str, timeline: Timeline, period_s: float, log: list[tuple[str, float]],
                 fail_at_s: float | None = None) -> None:
        self.name = name
        self.log = log
        self.fail_at_s = fail_at_s
        self.error: BaseException | None = None
        self.loop = FixedRateLoop(LockstepClock(timeline), period_s, self._tick)

    def _tick(self, _k: int, t_s: float, _period_s: float) -> None:
        if self.fail_at_s is not None and t_s >= self.fail_at_s:
            raise RuntimeError("boom")
        self.log.append((self.name, round(t_s, 6)))

    def run_tick(self) -> None:
        try:
            self.loop.run(max_ticks=1)
        except RuntimeError as exc:
            self.error = exc
            raise


def test_a_wait_runs_every_station_due_in_deadline_order() -> None:
    timeline = Timeline()
    timeline.advance_to(0.3)  # the stations come up at some moment after the simulation
    log: list[tuple[str, float]] = []
    a = Stepped("a", timeline, 0.025, log)
    b = Stepped("b", timeline, 0.04, log)
    clock = TeamClock(timeline, [a, b])
    clock.sleep_until(0.5)
    assert clock.now_s() == pytest.approx(0.5)
    times = [t for _, t in log]
    assert times == sorted(times)  # one shared time line, never back
    assert [t for n, t in log if n == "a"] == pytest.approx([0.3 + 0.025 * k for k in range(9)])
    assert [t for n, t in log if n == "b"] == pytest.approx([0.3 + 0.04 * k for k in range(6)])
    clock.sleep_until(0.6)  # the next wait goes on where the last one stopped
    assert [t for n, t in log if n == "a"][9] == pytest.approx(0.525)


def test_a_station_whose_tick_raised_drops_out_and_the_others_fly_on() -> None:
    timeline = Timeline()
    log: list[tuple[str, float]] = []
    bad = Stepped("bad", timeline, 0.025, log, fail_at_s=0.1)
    good = Stepped("good", timeline, 0.025, log)
    clock = TeamClock(timeline, [bad, good])
    clock.sleep_until(1.0)
    assert isinstance(bad.error, RuntimeError)
    assert max(t for n, t in log if n == "bad") < 0.1
    assert len([1 for n, _ in log if n == "good"]) == 41
    assert timeline.t_s == pytest.approx(1.0)


def test_a_stopped_loop_does_not_hang_the_wait() -> None:
    timeline = Timeline()
    log: list[tuple[str, float]] = []
    s = Stepped("s", timeline, 0.025, log)
    s.loop.stop()  # run() returns at once without a tick: the wait must not spin on it
    clock = TeamClock(timeline, [s])
    clock.sleep_until(0.2)
    assert log == [] and timeline.t_s == pytest.approx(0.2)
