"""A fault flight's result: the cases, what was watched, and the numbers judged from it.

Heights are motion capture's, in the station's floor reference; times are the SITL's simulated
seconds. See tests/e2e/fault_flight.py for how a flight is flown and watched.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from sitl.fault_frames import Counters, Direction

REST_ALT_M = 0.06  # the station's floor reference: its altitude of a vehicle standing on the floor
SETPOINT_M = 1.0
MODE_LAND = 9
FLOOR_BAND_M = 0.03  # within this of the resting altitude: on the floor


@dataclass(frozen=True, slots=True)
class FaultCase:
    """A fault and the response the station's policy documents for it."""

    name: str
    direction: Direction
    duration_s: float
    drop: bool
    loss: float = 0.0
    bitflip: float = 0.0
    documented: str = ""
    kill: bool = False  # the fault is the station's process killed (SIGKILL), not the link's

    @property
    def lands(self) -> bool:
        """A lost link or a killed station must end in a landing; a lossy link keeps flying."""
        return self.drop or self.kill


CASES: dict[str, FaultCase] = {c.name: c for c in (
    FaultCase("downlink", Direction.DOWN, 15.0, True,
              documented="station blind >1 s: requests LAND (uplink works), then goes quiet"),
    FaultCase("uplink", Direction.UP, 15.0, True,
              documented="vehicle hears nothing: its own GCS failsafe lands it"),
    FaultCase("both", Direction.BOTH, 15.0, True,
              documented="LAND requests lost; vehicle's failsafe lands it"),
    FaultCase("lossy", Direction.BOTH, 60.0, False, loss=0.3, bitflip=0.05,
              documented="30 % loss + 5 % flips: any frame is proof of life; keeps holding"),
    # the window only marks the moment (nothing dropped): the station is SIGKILLed then
    FaultCase("sigkill", Direction.BOTH, 0.01, False, kill=True,
              documented="station process killed: its guardian takes the link, lands it"),
)}


@dataclass
class FlightResult:
    """What happened, in simulated seconds, plus the numbers the suite asserts on."""

    case: FaultCase
    profile: str
    transport: str
    speedup: float
    exit_code: int
    stderr: str
    summary: dict[str, Any] | None
    phases: list[tuple[float, str]]  # (wall, phase) from --live
    t_s: np.ndarray  # mocap times
    alt_m: np.ndarray  # height, the station's floor reference (REST_ALT_M on the floor)
    fault_start_s: float | None
    fault_end_s: float | None
    heartbeats: list[tuple[float, bool, int]]  # (sim t, armed, custom mode)
    texts: list[tuple[float, str]]
    params: dict[str, float]
    up: Counters
    down: Counters
    wall_s: float
    overrides: list[tuple[float, int]]  # (sim t, throttle us) of every override that got through
    sent: list[tuple[float, str, str, int]]  # (sim t, fate, kind, value) of the station's frames

    # ------------------------------------------------------------ derived numbers
    @property
    def reason(self) -> str:
        """fly's last stderr line (its one-line reason when it failed)."""
        lines = self.stderr.strip().splitlines()
        return lines[-1] if lines else ""

    @property
    def airborne(self) -> np.ndarray:
        """Mask of samples from the first take-off on."""
        up = np.nonzero(self.alt_m > REST_ALT_M + 0.1)[0]
        mask = np.zeros(self.alt_m.shape, bool)
        if up.size:
            mask[up[0]:] = True
        return mask

    @property
    def max_over_setpoint_m(self) -> float:
        """Highest height minus the setpoint (negative: never reached it)."""
        return float(self.alt_m.max() - SETPOINT_M) if self.alt_m.size else float("nan")

    @property
    def max_over_at_s(self) -> float | None:
        """When the highest height was, in seconds after the fault's start (negative: before
        it, a take-off overshoot, say)."""
        if not self.alt_m.size or self.fault_start_s is None:
            return None
        return float(self.t_s[int(np.argmax(self.alt_m))] - self.fault_start_s)

    def _after_fault(self) -> np.ndarray:
        assert self.fault_start_s is not None
        return self.t_s >= self.fault_start_s

    @property
    def touchdown_s(self) -> float | None:
        """First time on the floor after the fault started (None: never, or no fault)."""
        if self.fault_start_s is None:
            return None
        idx = np.nonzero(self._after_fault() & (self.alt_m <= REST_ALT_M + FLOOR_BAND_M))[0]
        return float(self.t_s[idx[0]]) if idx.size else None

    @property
    def touchdown_speed_mps(self) -> float | None:
        """Descent speed just before contact: the slope of the last 0.25 s above the floor."""
        t_c = self.touchdown_s
        if t_c is None:
            return None
        sel = (self.t_s >= t_c - 0.25) & (self.t_s <= t_c)
        if sel.sum() < 3:
            return None
        slope = np.polyfit(self.t_s[sel] - t_c, self.alt_m[sel], 1)[0]
        return float(max(0.0, -slope))

    @property
    def disarm_s(self) -> float | None:
        """First sign of a disarm after the fault: a disarm text or a disarmed heartbeat."""
        if self.fault_start_s is None:
            return None
        t0 = self.fault_start_s
        hb = [t for t, armed, _ in self.heartbeats if t >= t0 and not armed]
        txt = [t for t, text in self.texts if t >= t0 and "disarm" in text.lower()]
        times = hb[:1] + txt[:1]
        return min(times) if times else None

    @property
    def land_mode_s(self) -> float | None:
        """First heartbeat in LAND after the fault (1 Hz: up to a second late)."""
        if self.fault_start_s is None:
            return None
        ts = [t for t, _, mode in self.heartbeats if t >= self.fault_start_s and mode == MODE_LAND]
        return ts[0] if ts else None

    @property
    def failsafe_texts(self) -> list[tuple[float, str]]:
        """The vehicle's failsafe texts after the fault started."""
        t0 = self.fault_start_s if self.fault_start_s is not None else float("inf")
        return [(t, s) for t, s in self.texts if t >= t0 and "failsafe" in s.lower()]

    @property
    def open_loop_s(self) -> float | None:
        """Seconds the vehicle flew on its last command before its own failsafe acted (only
        when the uplink was dead: otherwise the station's LAND got through)."""
        uplink_dead = self.case.drop and self.case.direction is not Direction.DOWN
        if self.fault_start_s is None or not uplink_dead:
            return None
        starts = [t for t, _ in self.failsafe_texts]
        if self.land_mode_s is not None:
            starts.append(self.land_mode_s)
        return (min(starts) - self.fault_start_s) if starts else None

    @property
    def open_loop_drift_m(self) -> tuple[float, float] | None:
        """(height change, widest excursion) from the fault's start to the failsafe."""
        dt = self.open_loop_s
        if dt is None or self.fault_start_s is None:
            return None
        sel = (self.t_s >= self.fault_start_s) & (self.t_s <= self.fault_start_s + dt)
        if not sel.any():
            return None
        seg = self.alt_m[sel]
        return float(seg[-1] - seg[0]), float(np.max(np.abs(seg - seg[0])))

    @property
    def hold_during_fault_m(self) -> float | None:
        """Worst |height - setpoint| while the fault lasted."""
        if self.fault_start_s is None or self.fault_end_s is None:
            return None
        sel = (self.t_s >= self.fault_start_s) & (self.t_s <= self.fault_end_s)
        return float(np.max(np.abs(self.alt_m[sel] - SETPOINT_M))) if sel.any() else None

    @property
    def pre_fault_rms_m(self) -> float | None:
        """RMS height error over the 10 s before the fault: how well the run flew at all (a
        machine too loaded for the speed-up shows here first)."""
        if self.fault_start_s is None:
            return None
        sel = (self.t_s >= self.fault_start_s - 10.0) & (self.t_s < self.fault_start_s)
        if not sel.any():
            return None
        return float(np.sqrt(np.mean((self.alt_m[sel] - SETPOINT_M) ** 2)))

    @property
    def last_throttle_us(self) -> tuple[int, float, float] | None:
        """(the last throttle the vehicle received before the fault, the median and the
        half-width of the 5-95 % band of the 10 s before): what it flies open-loop on."""
        if self.fault_start_s is None:
            return None
        t0 = self.fault_start_s
        before = [thr for t, thr in self.overrides if t0 - 10.0 <= t < t0]
        if not before:
            return None
        lo, mid, hi = np.percentile(before, (5, 50, 95))
        return before[-1], float(mid), float(hi - lo) / 2.0

    @property
    def gap_throttle_us(self) -> tuple[int, int, int, float | None] | None:
        """What the station sent once it could no longer see (downlink dead, uplink alive):
        (the lowest and highest throttle in the fault's first 0.5 s, the median of the next
        second, the seconds until it released the overrides, None if it never did)."""
        if self.fault_start_s is None or self.case.direction is not Direction.DOWN:
            return None
        t0 = self.fault_start_s
        first = [thr for t, thr in self.overrides if t0 <= t < t0 + 0.5 and thr]
        later = [thr for t, thr in self.overrides if t0 + 0.5 <= t < t0 + 1.5 and thr]
        released = [t - t0 for t, thr in self.overrides if t >= t0 and thr == 0]
        if not first:
            return None
        return (min(first), max(first), int(np.median(later)) if later else 0,
                released[0] if released else None)

    @property
    def station_after_fault(self) -> dict[str, Any] | None:
        """What the station sent from the fault on, in seconds after its start: its LAND
        requests (SET_MODE 9, whatever became of them), when it released the overrides (throttle
        0), and its last frame of any kind (then it was silent, or fly had ended)."""
        if self.fault_start_s is None:
            return None
        t0 = self.fault_start_s
        after = [(t - t0, kind, v) for t, _, kind, v in self.sent if t >= t0]
        lands = [round(t, 2) for t, kind, v in after if kind == "set_mode" and v == MODE_LAND]
        released = [t for t, kind, v in after if kind == "override" and v == 0]
        return {"land_requests_s": lands,
                "released_s": round(released[0], 2) if released else None,
                "last_frame_s": round(after[-1][0], 2) if after else None,
                "heartbeats": sum(kind == "heartbeat" for _, kind, _ in after)}

    def _score(self) -> str:
        s = self.summary or {}
        keys = ("status", "rms_error_m", "max_error_m", "error_source", "link_down_s")
        return ", ".join(f"{k} {s[k]}" for k in keys if k in s) or "none"

    def report(self) -> str:
        """The run in one long line, for assertion messages and the log."""
        def f(x: float | None, unit: str = " s") -> str:
            return "none" if x is None else f"{x:.2f}{unit}"

        t0 = self.fault_start_s

        def rel(t: float | None) -> float | None:
            return None if t is None or t0 is None else t - t0

        drift = self.open_loop_drift_m
        parts = [
            f"{self.case.name}/{self.profile}/{self.transport} x{self.speedup:g}: exit "
            f"{self.exit_code} ({self.reason!r})",
            f"fault at t={f(t0)}",
            f"hold RMS before it {f(self.pre_fault_rms_m, ' m')}",
            f"max over setpoint {f(self.max_over_setpoint_m, ' m')} at {f(self.max_over_at_s)}",
            f"touchdown {f(rel(self.touchdown_s))} after the fault at "
            f"{f(self.touchdown_speed_mps, ' m/s')}",
            f"disarmed {f(rel(self.disarm_s))} after",
            f"LAND seen {f(rel(self.land_mode_s))} after",
            f"failsafe texts {[(round(t - (t0 or 0), 1), s) for t, s in self.failsafe_texts]}",
            f"open-loop {f(self.open_loop_s)}, drift "
            f"{drift and tuple(round(d, 3) for d in drift)}",
            f"last throttle before the fault (us, hold median, ±5-95 %) {self.last_throttle_us}",
            f"station's throttle blind (min, max 0-0.5 s, median 0.5-1.5 s, released after s) "
            f"{self.gap_throttle_us}",
            f"station after the fault {self.station_after_fault}",
            f"hold dev in fault {f(self.hold_during_fault_m, ' m')}",
            f"params {self.params}",
            f"fly's own score {self._score()}",
            f"proxy up [{self.up.line()}] down [{self.down.line()}]",
            f"{self.wall_s:.0f} s wall",
        ]
        return "; ".join(parts)

    def save(self, path: Path) -> None:
        """The flight's series to an .npz (heights, heartbeats, what the station sent), for a
        look afterwards."""
        np.savez_compressed(
            path, t_s=self.t_s, alt_m=self.alt_m,
            fault=np.array([self.fault_start_s or np.nan, self.fault_end_s or np.nan]),
            heartbeats=np.array(self.heartbeats, dtype=float).reshape(-1, 3),
            overrides=np.array(self.overrides, dtype=float).reshape(-1, 2),
            sent=np.array([(t, v) for t, _, _, v in self.sent], dtype=float).reshape(-1, 2),
            sent_kind=np.array([f"{fate}:{kind}" for _, fate, kind, _ in self.sent]),
            report=np.array(self.report()))
