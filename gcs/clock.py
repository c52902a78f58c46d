"""Injectable clocks for the fixed-rate loop: the real monotonic clock and a simulated one.

Control code never reads the wall clock; it asks a `Clock`. `MonotonicClock` sleeps coarsely and
then spins for the last stretch, because `time.sleep` alone overshoots by 0.1–1 ms under load and
the 25 ms loop's jitter floor is 1 ms p99. `ScaledClock` runs K times faster than real time so the
station can fly a SITL started with `--speedup K` on matching time.
"""

from __future__ import annotations

import time
from typing import Protocol


class Clock(Protocol):
    """Seconds on a monotonic time line, and a way to wait for a point on it."""

    def now_s(self) -> float:
        """Current time, seconds."""
        ...

    def sleep_until(self, t_s: float) -> None:
        """Return at (or as soon as possible after) time `t_s`."""
        ...


class MonotonicClock:
    """`time.monotonic` with a precise sleep: coarse sleep, then spin the last `spin_s`."""

    def __init__(self, spin_s: float = 0.0015) -> None:
        if spin_s < 0.0:
            raise ValueError(f"spin_s must be >= 0, got {spin_s}")
        self._spin_s = spin_s

    def now_s(self) -> float:
        """Seconds from `time.monotonic`."""
        return time.monotonic()

    def sleep_until(self, t_s: float) -> None:
        """Sleep until `t_s - spin_s`, then spin (yielding the GIL) until `t_s`."""
        remaining = t_s - time.monotonic()
        if remaining > self._spin_s:
            time.sleep(remaining - self._spin_s)
        while time.monotonic() < t_s:
            # sleep(0) releases the GIL so the link's reader and the UI keep running
            time.sleep(0)


class ScaledClock:
    """A clock that runs `speedup` times faster than the monotonic clock (for a sped-up SITL)."""

    def __init__(self, speedup: float, spin_s: float = 0.0015) -> None:
        if speedup <= 0.0:
            raise ValueError(f"speedup must be > 0, got {speedup}")
        self.speedup = speedup
        self._spin_s = spin_s
        self._t0 = time.monotonic()

    def now_s(self) -> float:
        """Scaled seconds since the clock was made (plus the monotonic origin)."""
        return self._t0 + (time.monotonic() - self._t0) * self.speedup

    def sleep_until(self, t_s: float) -> None:
        """Wait until the scaled time reaches `t_s`."""
        real_target = self._t0 + (t_s - self._t0) / self.speedup
        remaining = real_target - time.monotonic()
        if remaining > self._spin_s:
            time.sleep(remaining - self._spin_s)
        while time.monotonic() < real_target:
            time.sleep(0)


class SimClock:
    """A simulated clock for tests: `sleep_until` jumps time forward; `advance` adds time."""

    def __init__(self, t0_s: float = 0.0) -> None:
        self._t_s = t0_s

    def now_s(self) -> float:
        """The simulated time."""
        return self._t_s

    def sleep_until(self, t_s: float) -> None:
        """Jump to `t_s` (never backwards)."""
        self._t_s = max(self._t_s, t_s)

    def advance(self, dt_s: float) -> None:
        """Let `dt_s` seconds pass, e.g. to model the compute time of a tick."""
        if dt_s < 0.0:
            raise ValueError(f"dt_s must be >= 0, got {dt_s}")
        self._t_s += dt_s
