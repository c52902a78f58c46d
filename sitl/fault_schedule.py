"""The fault book of `sitl.fault_proxy`: standing settings per direction, timed windows, and
which faults act on a frame at a given proxy time. `FaultProxy` inherits it; its relay thread
reads `_effective` under the proxy's lock.
"""

from __future__ import annotations

import threading
import time
from dataclasses import dataclass

from sitl.fault_frames import Direction, FaultWindow, as_direction


@dataclass
class FaultSettings:
    """Standing faults of one direction."""

    loss: float = 0.0
    bitflip: float = 0.0
    delay_s: float = 0.0


def probability(name: str, p: float | None) -> None:
    """A ValueError unless `p` is None or in 0..1."""
    if p is not None and not 0.0 <= p <= 1.0:
        raise ValueError(f"{name} must be a probability in 0..1, got {p}")


class FaultSchedule:
    """Standing faults and fault windows; the proxy's state they read and write, declared."""

    time_scale: float
    _t0: float
    _cond: threading.Condition
    _settings: dict[Direction, FaultSettings]
    _windows: list[FaultWindow]
    _station_t_s: float | None

    def now_s(self) -> float:
        """Proxy time: simulated seconds since start()."""
        return (time.monotonic() - self._t0) * self.time_scale

    def monotonic_at(self, t_s: float) -> float:
        """The `time.monotonic()` reading at proxy time `t_s`."""
        return self._t0 + t_s / self.time_scale

    def set(self, direction: Direction | str, *, loss: float | None = None,
            bitflip: float | None = None, delay_s: float | None = None) -> None:
        """Standing faults from now on (None leaves a setting as it is)."""
        probability("loss", loss)
        probability("bitflip", bitflip)
        if delay_s is not None and not delay_s >= 0.0:
            raise ValueError(f"delay must be >= 0 s, got {delay_s}")
        with self._cond:
            for d in as_direction(direction).lanes():
                s = self._settings[d]
                s.loss = s.loss if loss is None else loss
                s.bitflip = s.bitflip if bitflip is None else bitflip
                s.delay_s = s.delay_s if delay_s is None else delay_s

    def drop(self, direction: Direction | str, duration_s: float, start_s: float = 0.0, *,
             from_station: bool = False) -> FaultWindow:
        """Drop everything one way (or both) for `duration_s`, from `start_s` after now (or
        after the first station arrives)."""
        return self.schedule(direction, start_s, duration_s, drop=True,
                             from_station=from_station)

    def schedule(self, direction: Direction | str, start_s: float, duration_s: float, *,
                 drop: bool = False, loss: float = 0.0, bitflip: float = 0.0,
                 delay_s: float = 0.0, from_station: bool = False) -> FaultWindow:
        """A fault window `start_s` after now, lasting `duration_s` (simulated seconds). With
        `from_station` it counts from the first station's arrival (its TCP connection, or its
        first byte on the pseudo-terminal), decided on the relay thread, so no frame of the
        station's first moments slips past. Over the standing settings the stronger loss and
        bit-flip rates and the longer delay act."""
        probability("loss", loss)
        probability("bitflip", bitflip)
        if not (duration_s > 0.0 and start_s >= 0.0 and delay_s >= 0.0):
            raise ValueError(f"a window needs start >= 0, duration > 0 and delay >= 0; got "
                             f"start {start_s}, duration {duration_s}, delay {delay_s}")
        t = start_s if from_station else self.now_s() + start_s
        w = FaultWindow(as_direction(direction), t, t + duration_s, drop, loss, bitflip,
                        delay_s, from_station)
        with self._cond:
            self._windows.append(w)
        return w

    @property
    def station_arrived_s(self) -> float | None:
        """Proxy time of the first station's arrival (None: not yet)."""
        with self._cond:
            return self._station_t_s

    def clear(self) -> None:
        """No faults from now on: windows and standing settings gone."""
        with self._cond:
            self._windows.clear()
            self._settings = {d: FaultSettings() for d in self._settings}

    def windows(self) -> list[FaultWindow]:
        """Every window still on the books."""
        with self._cond:
            return list(self._windows)

    def _effective(self, d: Direction, t_s: float) -> tuple[bool, FaultSettings]:
        base = self._settings[d]
        eff = FaultSettings(base.loss, base.bitflip, base.delay_s)
        dropping = False
        for w in self._windows:
            t = t_s
            if w.from_station:
                if self._station_t_s is None:
                    continue
                t -= self._station_t_s
            if d in w.direction.lanes() and w.start_s <= t < w.end_s:
                dropping = dropping or w.drop
                eff.loss = max(eff.loss, w.loss)
                eff.bitflip = max(eff.bitflip, w.bitflip)
                eff.delay_s = max(eff.delay_s, w.delay_s)
        return dropping, eff
