"""A fixed-rate loop on an injectable clock that measures itself.

Deadlines are absolute (`t0 + k * period`), so timing errors never accumulate. A tick whose
compute time exceeds the period, or a wake-up later than a whole period, is an overrun: the loop
skips ahead to the next deadline still in the future and counts the deadlines it missed rather
than running a burst of late ticks.
"""

from __future__ import annotations

import os
import threading
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from gcs.clock import Clock

TickFn = Callable[[int, float, float], None]
"""tick(k, t_s, dt_s): tick index, the tick's start time on the loop's clock, nominal period."""


@dataclass(frozen=True, slots=True)
class TickTiming:
    """Timing of one tick (seconds)."""

    k: int
    deadline_s: float
    start_s: float
    period_s: float  # start minus the previous tick's start (nominal for the first)
    jitter_s: float  # |period_s - nominal period|
    lateness_s: float  # start - deadline
    compute_s: float
    overrun: bool


@dataclass(frozen=True, slots=True)
class LoopStats:
    """Summary of the loop's timing over its recent window (seconds)."""

    nominal_period_s: float
    ticks: int
    overruns: int
    missed_deadlines: int
    period_mean_s: float
    jitter_p50_s: float
    jitter_p99_s: float
    jitter_max_s: float
    compute_p50_s: float
    compute_p99_s: float
    compute_max_s: float
    lateness_p99_s: float


def _make_realtime(priority: int) -> bool:
    """Put the calling thread under SCHED_FIFO; False where not permitted or not Linux.

    On a loaded 2-core machine an ordinary thread wakes 4–15 ms late now and then; a real-time
    thread wakes within tens of microseconds. The loop sleeps most of each period, so it
    cannot starve the rest of the system.
    """
    setter = getattr(os, "sched_setscheduler", None)
    if setter is None:
        return False
    try:
        setter(0, os.SCHED_FIFO, os.sched_param(priority))
    except (OSError, ValueError):
        return False
    return True


class FixedRateLoop:
    """Calls `tick` every `period_s` on `clock` until stopped; keeps timing statistics."""

    def __init__(self, clock: Clock, period_s: float, tick: TickFn, window: int = 12_000,
                 realtime_priority: int = 0) -> None:
        if period_s <= 0.0:
            raise ValueError(f"period_s must be > 0, got {period_s}")
        self.clock = clock
        self.realtime_priority = realtime_priority
        self.realtime = False  # True once the running thread got SCHED_FIFO
        self.period_s = period_s
        self._tick = tick
        self._stop = threading.Event()
        self._lock = threading.Lock()
        self._periods: deque[float] = deque(maxlen=window)
        self._jitters: deque[float] = deque(maxlen=window)
        self._computes: deque[float] = deque(maxlen=window)
        self._lateness: deque[float] = deque(maxlen=window)
        self._ticks = 0
        self._overruns = 0
        self._missed = 0
        self._last: TickTiming | None = None
        self._k = 0
        self._t0_s: float | None = None
        self._prev_start_s: float | None = None

    def stop(self) -> None:
        """Ask the loop to return after the current tick (thread-safe)."""
        self._stop.set()

    @property
    def stopping(self) -> bool:
        """True once `stop()` was called."""
        return self._stop.is_set()

    @property
    def next_deadline_s(self) -> float | None:
        """When the next tick is due (None before the first `run`)."""
        return None if self._t0_s is None else self._t0_s + self._k * self.period_s

    @property
    def last_timing(self) -> TickTiming | None:
        """The most recent tick's timing."""
        return self._last

    def run(self, max_ticks: int | None = None) -> None:
        """Run ticks until `stop()` (or `max_ticks` ticks); exceptions from `tick` propagate."""
        done = 0
        if self.realtime_priority > 0 and not self.realtime:
            self.realtime = _make_realtime(self.realtime_priority)
        if self._t0_s is None:
            self._t0_s = self.clock.now_s()
        while not self._stop.is_set() and (max_ticks is None or done < max_ticks):
            deadline = self._t0_s + self._k * self.period_s
            self.clock.sleep_until(deadline)
            start = self.clock.now_s()
            self._tick(self._k, start, self.period_s)
            end = self.clock.now_s()
            self._account(deadline, start, end)
            done += 1

    def _account(self, deadline: float, start: float, end: float) -> None:
        assert self._t0_s is not None
        period = self.period_s if self._prev_start_s is None else start - self._prev_start_s
        self._prev_start_s = start
        compute = end - start
        lateness = start - deadline
        overrun = compute > self.period_s or lateness > self.period_s
        next_k = self._k + 1
        if end > self._t0_s + next_k * self.period_s:
            # skip ahead to the first deadline still in the future; count the ones passed over
            behind = int((end - self._t0_s) / self.period_s) + 1
            with self._lock:
                self._missed += behind - next_k
            next_k = behind
            overrun = True
        timing = TickTiming(
            k=self._k,
            deadline_s=deadline,
            start_s=start,
            period_s=period,
            jitter_s=abs(period - self.period_s),
            lateness_s=lateness,
            compute_s=compute,
            overrun=overrun,
        )
        with self._lock:
            self._ticks += 1
            self._overruns += int(overrun)
            self._periods.append(period)
            self._jitters.append(timing.jitter_s)
            self._computes.append(compute)
            self._lateness.append(lateness)
            self._last = timing
        self._k = next_k

    def stats(self) -> LoopStats:
        """A consistent snapshot of the timing statistics (thread-safe)."""
        with self._lock:  # copy fast under the lock; the loop thread must not wait on numpy
            raw = (list(self._periods), list(self._jitters), list(self._computes),
                   list(self._lateness))
            ticks, overruns, missed = self._ticks, self._overruns, self._missed
        periods, jitters, computes, lateness = (np.asarray(a, dtype=float) for a in raw)

        def pct(a: np.ndarray, q: float) -> float:
            return float(np.percentile(a, q)) if a.size else 0.0

        return LoopStats(
            nominal_period_s=self.period_s,
            ticks=ticks,
            overruns=overruns,
            missed_deadlines=missed,
            period_mean_s=float(periods.mean()) if periods.size else 0.0,
            jitter_p50_s=pct(jitters, 50),
            jitter_p99_s=pct(jitters, 99),
            jitter_max_s=float(jitters.max()) if jitters.size else 0.0,
            compute_p50_s=pct(computes, 50),
            compute_p99_s=pct(computes, 99),
            compute_max_s=float(computes.max()) if computes.size else 0.0,
            lateness_p99_s=pct(lateness, 99),
        )
