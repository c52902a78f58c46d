"""The cheap part of `quadgcs logs check`, live in the station: link loss over the last 10 s,
the loop's overruns, and vibration; a message for the pilot when one crosses its warning
level, and one summary line at the end of a flight.

Everything is incremental and O(1) per call on the loop's thread: the link's counters are
sampled once a second into a ring of eleven, an overrun is a counter, and vibration is an
exponentially weighted mean (the accelerometer's slow part, about 1 s) and mean square of what
is left (about 5 s) per axis. The levels are `logs.check`'s own warning thresholds, so what the
pilot is told during the flight is what the review of its recording will say.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, field

from firmware_link.records import Imu
from firmware_link.stats import LinkStats
from gcs.station.loop import TickTiming
from logs.check.result import Status, judge
from logs.check.thresholds import Threshold, defaults

WINDOW_S = 10.0  # link loss and overruns are told over this long
SAMPLE_S = 1.0  # the link's counters are sampled this often
MEAN_TC_S = 1.0  # vibration is what the accelerometer does about its mean over about this
POWER_TC_S = 5.0  # … averaged in power over about this
REPEAT_S = 30.0  # a warning still true is told again after this long
AXES = ("x", "y", "z")


@dataclass
class _Vibe:
    mean: list[float] = field(default_factory=lambda: [math.nan] * 3)
    power: list[float] = field(default_factory=lambda: [0.0] * 3)
    last_t_s: float = math.nan
    flown_s: float = 0.0  # seconds of samples in the air
    energy: list[float] = field(default_factory=lambda: [0.0] * 3)  # ∫ deviation² dt


class LiveCheck:
    """Feed it IMU records (`imu`) and each tick (`tick`); it returns what to tell the pilot."""

    def __init__(self, table: dict[str, Threshold] | None = None) -> None:
        t = table or defaults()
        self.loss = t["link.loss_pct"]
        self.overruns = t["loop.overruns_pct"]
        self.vibe = {a: t[f"vibration.acc_rms_{a}_mps2"] for a in AXES}
        self._link: deque[tuple[float, int, int]] = deque(maxlen=int(WINDOW_S / SAMPLE_S) + 1)
        self._ticks: deque[tuple[float, int, int]] = deque(maxlen=int(WINDOW_S / SAMPLE_S) + 1)
        self._n_ticks = 0
        self._n_overruns = 0
        self._worst_loss_pct = 0.0
        self._flying = False
        self._v = _Vibe()
        self._told: dict[str, float] = {}
        self.faults = 0  # exceptions caught (a bug here must never stop the loop)
        self._fault_text = ""

    # ------------------------------------------------------------------ inputs
    def imu(self, r: Imu) -> None:
        """One accelerometer sample (only those in the air count). Never raises: the loop
        calls it (a fault is counted and told once by the next `tick`)."""
        try:
            self._imu(r)
        except Exception as exc:
            self._fault(exc)

    def tick(self, t_s: float, flying: bool, stats: LinkStats,
             timing: TickTiming | None) -> list[str]:
        """One tick: the messages to show now (usually none). Never raises."""
        try:
            out = self._tick(t_s, flying, stats, timing)
        except Exception as exc:
            self._fault(exc)
            out = []
        if self._fault_text:
            out.append(self._fault_text)
            self._fault_text = ""
        return out

    def _fault(self, exc: Exception) -> None:
        self.faults += 1
        if self.faults == 1:
            self._fault_text = f"live check failed (it stops being told): {exc!r}"

    def _imu(self, r: Imu) -> None:
        v = self._v
        if not self._flying:
            v.last_t_s = math.nan
            return
        dt = r.t_s - v.last_t_s if math.isfinite(v.last_t_s) else 0.0
        v.last_t_s = r.t_s
        if dt < 0.0 or dt > 1.0:
            return
        a_mean = 1.0 - math.exp(-dt / MEAN_TC_S)
        a_pow = 1.0 - math.exp(-dt / POWER_TC_S)
        for i, acc in enumerate(r.acc_b):
            if not math.isfinite(acc):
                return
            if not math.isfinite(v.mean[i]):
                v.mean[i] = acc
            dev = acc - v.mean[i]
            v.mean[i] += a_mean * dev
            v.power[i] += a_pow * (dev * dev - v.power[i])
            v.energy[i] += dev * dev * dt
        v.flown_s += dt

    def _tick(self, t_s: float, flying: bool, stats: LinkStats,
              timing: TickTiming | None) -> list[str]:
        self._flying = flying
        self._n_ticks += 1
        self._n_overruns += int(timing is not None and timing.overrun)
        out: list[str] = []
        if not self._link or t_s - self._link[-1][0] >= SAMPLE_S:
            self._link.append((t_s, stats.rx_messages, stats.lost_messages))
            self._ticks.append((t_s, self._n_ticks, self._n_overruns))
            out += self._judge(t_s)
        return out

    # ------------------------------------------------------------------ judging
    def loss_pct(self) -> float:
        """Frames lost over the last 10 s, % (0 before there is a window)."""
        if len(self._link) < 2:
            return 0.0
        (_t0, rx0, lost0), (_t1, rx1, lost1) = self._link[0], self._link[-1]
        lost, got = lost1 - lost0, rx1 - rx0
        return 100.0 * lost / (lost + got) if lost + got > 0 else 0.0

    def vibration_rms(self) -> tuple[float, float, float]:
        """The current accelerometer RMS about its mean, per axis (m/s²)."""
        return tuple(math.sqrt(p) for p in self._v.power)  # type: ignore[return-value]

    def _tell(self, key: str, t_s: float, text: str, out: list[str]) -> None:
        if t_s - self._told.get(key, -math.inf) >= REPEAT_S:
            self._told[key] = t_s
            out.append(text)

    def _judge(self, t_s: float) -> list[str]:
        out: list[str] = []
        full = len(self._link) == self._link.maxlen  # a whole 10 s window: judged on it only
        loss = self.loss_pct()
        if full:
            self._worst_loss_pct = max(self._worst_loss_pct, loss)
        if full and judge(loss, self.loss) is not Status.PASS:
            self._tell("loss", t_s, f"link loss {loss:.0f} % over {WINDOW_S:.0f} s", out)
        (_t0, n0, o0), (_t1, n1, o1) = self._ticks[0], self._ticks[-1]
        overrun_pct = 100.0 * (o1 - o0) / max(n1 - n0, 1)
        if full and judge(overrun_pct, self.overruns) is not Status.PASS:
            self._tell("loop", t_s, f"loop overruns: {o1 - o0} of {n1 - n0} ticks in the last "
                       f"{WINDOW_S:.0f} s", out)
        if self._flying and self._v.flown_s > POWER_TC_S:
            rms = self.vibration_rms()
            bad = [(r, a) for r, a in zip(rms, AXES, strict=True)
                   if judge(r, self.vibe[a]) is not Status.PASS]
            if bad:
                r, a = max(bad)
                self._tell("vibe", t_s, f"vibration high: {r:.1f} m/s² RMS on {a}", out)
        return out

    def summary(self) -> tuple[Status, str]:
        """The flight's live checks in one line, and their worst status: the worst 10 s of link
        loss, every overrun, and the accelerometer's RMS over the whole time in the air (as
        `logs check` measures it)."""
        overrun_pct = 100.0 * self._n_overruns / max(self._n_ticks, 1)
        flight_rms = [math.sqrt(e / self._v.flown_s) if self._v.flown_s > 0 else 0.0
                      for e in self._v.energy]
        worst_axis = max(range(3), key=lambda i: flight_rms[i])
        vibe = flight_rms[worst_axis]
        statuses = [judge(self._worst_loss_pct, self.loss), judge(overrun_pct, self.overruns),
                    judge(vibe, self.vibe[AXES[worst_axis]])]
        status = next((s for s in (Status.FAIL, Status.WARN) if s in statuses), Status.PASS)
        return status, (f"live checks {status.value}: link loss worst {self._worst_loss_pct:.1f} "
                        f"% per {WINDOW_S:.0f} s, {self._n_overruns} overruns in "
                        f"{self._n_ticks} ticks, vibration {vibe:.2f} m/s² RMS in the air "
                        f"({AXES[worst_axis]}); quadgcs logs check reviews the recording")
