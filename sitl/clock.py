"""Pacing of simulated time against the wall clock (`--speedup K`)."""

from __future__ import annotations

import time
from collections.abc import Callable


class PacedClock:
    """Maps simulated time to a monotonic wall deadline: sim t runs K times faster than real."""

    def __init__(
        self, speedup: float = 1.0, monotonic: Callable[[], float] = time.monotonic
    ) -> None:
        if not speedup > 0.0:
            raise ValueError(f"speedup: expected a number > 0, got {speedup!r}")
        self.speedup = speedup
        self._monotonic = monotonic
        self._wall0 = monotonic()
        self._sim0 = 0.0

    def wall_deadline(self, sim_t_s: float) -> float:
        """Monotonic time at which simulated time `sim_t_s` is due."""
        return self._wall0 + (sim_t_s - self._sim0) / self.speedup

    def seconds_until(self, sim_t_s: float) -> float:
        """Wall seconds to wait before `sim_t_s` is due (negative when late)."""
        return self.wall_deadline(sim_t_s) - self._monotonic()

    def resync(self, sim_t_s: float) -> None:
        """Forget a backlog: treat `sim_t_s` as due now (after a long stall)."""
        self._wall0 = self._monotonic()
        self._sim0 = sim_t_s
