"""Telemetry that arrives late and all at once, integrated at the vehicle's own sample times.

A link that stalls and then delivers (a starved SITL, a radio that retries, a USB hub that
buffers) hands the station a fraction of a second of samples in one tick. Through the silence
the filter coasted with no acceleration (`EstimatorParams.imu_stale_s`); taken as one averaged
sample at the end, the burst's accelerations count for one tick instead of the whole silence,
so in a climb the estimate falls behind by the climb it missed (a synthetic 1 m climb with
0.2 s held back in every 0.5 s: 63 cm at worst, against 2 cm when nothing is held).

The estimator's state is kept as it was before the silence, with the ticks that came during
it. When a burst ends the silence, that state comes back and the ticks are run again, each
with the samples that would have reached it on time: an IMU sample at the station time its
own timestamp maps to (`time_usec`, by the offset of samples that arrived promptly), sonar
readings (which carry no timestamp in 3.2.1's RANGEFINDER) spread over the burst's span in
the order they came. The estimates the controller already used are not changed, only what
the filter knows from now on.

A sample with the vehicle time of one taken in the kept second is the link delivering a
frame twice (a retrying radio, two routes to one vehicle): it is dropped and counted, not
integrated again. One that is merely out of order is placed at its time like any late one.
A vehicle time ahead of the station's clock by more than the kept second (a frame garbled
in a way the CRC missed) is integrated as prompt but does not teach the offset.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from typing import Protocol

from firmware_link.records import Attitude, Imu, Rangefinder

USEC = 1e-6


def average_imu(imus: Sequence[Imu]) -> Imu | None:
    """Samples averaged into one: less vibration noise, same information (None if none)."""
    if not imus:
        return None
    if len(imus) == 1:
        return imus[0]
    n = len(imus)
    acc = (sum(i.acc_b[0] for i in imus) / n, sum(i.acc_b[1] for i in imus) / n,
           sum(i.acc_b[2] for i in imus) / n)
    last = imus[-1]
    return Imu(last.t_s, last.sysid, acc, last.gyro_b, last.source, last.time_usec)


@dataclass(frozen=True, slots=True)
class EstimatorTick:
    """What one control tick gives the estimator (the flight core's `TickInputs` as the filter
    takes them: IMU samples, sonar readings, the newest attitude, and what the core derived),
    kept so a late burst can run the ticks again."""

    t_s: float
    imus: tuple[Imu, ...]
    sonars: tuple[Rangefinder, ...]
    attitude: Attitude | None
    at_rest: bool
    baro_alt_m: float | None
    # the vertical acceleration the station's last stick command asked for (None: not known)
    command_acc_mps2: float | None = None
    # the station knows the vehicle is off the floor (see AltEstimator.update)
    airborne: bool = False
    # the take-off felt the vehicle leave the floor last tick: (altitude m, velocity m/s) then
    liftoff: tuple[float, float] | None = None


class Restorable(Protocol):
    """An estimator whose state can be kept and put back."""

    def snapshot(self) -> object: ...

    def restore(self, state: object) -> None: ...


@dataclass(frozen=True, slots=True)
class CatchUpParams:
    late_s: float = 0.035  # samples due this long before the last tick came late: replay
    max_window_s: float = 1.0  # later than this, a lost link rather than a late one: no replay
    offset_window_s: float = 2.0  # prompt samples this recent set the vehicle-to-station offset


@dataclass(frozen=True, slots=True)
class _Kept:
    inputs: EstimatorTick
    state: object  # the estimator's state before this tick


class CatchUp:
    """Keeps the last second of ticks with the state before each, and runs them again when
    samples arrive that were due at earlier ticks."""

    def __init__(self, params: CatchUpParams | None = None) -> None:
        self.params = params or CatchUpParams()
        self.replays = 0  # late samples integrated at their own times
        self.dropped = 0  # IMU samples the link delivered twice
        self.implausible = 0  # vehicle times ahead of the station's clock: not learned from
        self._taken: dict[int, float] = {}  # vehicle time -> tick, oldest first, in the window
        self._kept: deque[_Kept] = deque()
        # (tick, rx time - vehicle time), offsets rising: an entry with a later, smaller one
        # can never be the window's least again, so it is dropped when that one comes
        self._offsets: deque[tuple[float, float]] = deque()

    def tick(self, est: Restorable, inputs: EstimatorTick,
             step: Callable[[EstimatorTick], object]) -> object:
        """Run `step` on this tick's inputs, or on the kept ticks again from the earliest one
        that the late samples were due at; returns the last step's result."""
        p = self.params
        inputs = self._without_repeats(inputs)
        while self._kept and self._kept[0].inputs.t_s < inputs.t_s - p.max_window_s:
            self._kept.popleft()
        offset = self._offset_s()
        first = self._replay_from(inputs, offset)
        if first is None:
            self._kept.append(_Kept(inputs, est.snapshot()))
            result = step(inputs)
        else:
            assert offset is not None
            replayed = [k.inputs for k in list(self._kept)[first:]]
            est.restore(self._kept[first].state)
            for _ in range(len(self._kept) - first):
                self._kept.pop()
            result = None
            for t in _redistributed(replayed, inputs, offset):
                self._kept.append(_Kept(t, est.snapshot()))
                result = step(t)
            self.replays += 1
        self._learn_offset(inputs)
        return result

    def _without_repeats(self, inputs: EstimatorTick) -> EstimatorTick:
        """The tick's inputs without the IMU samples already taken."""
        taken, cutoff = self._taken, inputs.t_s - self.params.max_window_s
        while taken:
            oldest = next(iter(taken))
            if taken[oldest] >= cutoff:
                break
            del taken[oldest]
        kept: list[Imu] = []
        for imu in inputs.imus:
            if imu.time_usec > 0:
                if imu.time_usec in taken:
                    self.dropped += 1
                    continue
                taken[imu.time_usec] = inputs.t_s
            kept.append(imu)
        return inputs if len(kept) == len(inputs.imus) else replace(inputs, imus=tuple(kept))

    def _replay_from(self, inputs: EstimatorTick, offset_s: float | None) -> int | None:
        """Index of the kept tick to run again from, None when this tick's samples are on time."""
        if offset_s is None or not inputs.imus or not self._kept:
            return None
        if any(i.time_usec <= 0 for i in inputs.imus):
            return None  # samples without the vehicle's time: nothing to place them by
        due = min(i.time_usec for i in inputs.imus) * USEC + offset_s  # reordered: the earliest
        if due >= self._kept[-1].inputs.t_s - self.params.late_s:
            return None
        if due < self._kept[0].inputs.t_s:
            return None  # older than what is kept: a long loss, a reboot, a clock that drifts
        k = len(self._kept) - 1
        while k >= 0 and self._kept[k].inputs.t_s >= due:
            k -= 1
        return k + 1

    def _learn_offset(self, inputs: EstimatorTick) -> None:
        if not inputs.imus or inputs.imus[-1].time_usec <= 0:
            return
        last = inputs.imus[-1]
        offset = last.t_s - last.time_usec * USEC
        least = self._offset_s()
        if least is not None and offset < least - self.params.max_window_s:
            self.implausible += 1
            return
        offsets = self._offsets
        while offsets and offsets[-1][1] >= offset:
            offsets.pop()
        offsets.append((inputs.t_s, offset))
        while offsets[0][0] < inputs.t_s - self.params.offset_window_s:
            offsets.popleft()

    def _offset_s(self) -> float | None:
        """Station time minus vehicle time of the promptest recent sample (the least delay)."""
        return self._offsets[0][1] if self._offsets else None


def _redistributed(earlier: list[EstimatorTick], now: EstimatorTick,
                   offset_s: float) -> list[EstimatorTick]:
    """The earlier ticks and this one, each with this tick's samples that were due at it."""
    ticks = [*earlier, now]
    times = [t.t_s for t in ticks]
    due = [min(max(i.time_usec * USEC + offset_s, times[0]), now.t_s) for i in now.imus]
    # no timestamps: spread over the burst's span, in their order, ending at the last IMU
    first, last = due[0], due[-1]
    m = len(now.sonars)
    sonar_due = [last if m == 1 else first + (last - first) * (j + 1) / m for j in range(m)]
    out: list[EstimatorTick] = []
    lo = -float("inf")
    for k, t in enumerate(ticks):
        hi = t.t_s if k < len(ticks) - 1 else float("inf")
        imus = tuple(i for i, d in zip(now.imus, due, strict=True) if lo < d <= hi)
        late = tuple(replace(s, t_s=t.t_s)
                     for s, d in zip(now.sonars, sonar_due, strict=True) if lo < d <= hi)
        if k == len(ticks) - 1:  # this tick: everything it brought is placed above
            out.append(replace(now, imus=imus, sonars=late))
        else:
            out.append(replace(t, imus=t.imus + imus, sonars=t.sonars + late))
        lo = hi
    return out
