"""One `quadgcs fly` through the fault proxy, watched from outside the link it breaks.

The SITL runs as its own program; the station is the real CLI (`python -m gcs fly --connect
<proxy> --json --live`), so what is tested is what a user runs. The fault hits only the vehicle
link. Height comes from the motion-capture endpoint (which the fault does not touch), and the
vehicle's arming state, mode and texts from a UDP endpoint of the SITL that only listens (it
never sends a heartbeat, so it cannot keep the vehicle's GCS failsafe from firing).

Times are the SITL's simulated seconds (mocap `time_usec`); what is stamped on the wall clock
(heartbeats, the fault window) is mapped through the mocap stream's arrival times.
"""

from __future__ import annotations

import concurrent.futures
import contextlib
import functools
import json
import os
import socket
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from sitl.fault_frames import Counters, Direction
from sitl.fault_proxy import FaultProxy
from tests.e2e.fault_watch import MavWatcher, SimClockMap, StationTap

ROOT = Path(__file__).resolve().parents[2]
REST_ALT_M = 0.06  # the station's floor reference: its altitude of a vehicle standing on the floor
SETPOINT_M = 1.0
FAULT_AFTER_HOLD_S = 30.0
MODE_LAND = 9
FLOOR_BAND_M = 0.03  # within this of the resting altitude: on the floor
# Real time, three flights at a time, by default: on a shared two-core machine, two 2x flights
# at a time lost their hold before any fault in 5 of 18 flights (RMS 0.07 to 1.43 m over the
# 10 s before it); all 9 real-time flights held within 0.03 m. QUADGCS_FAULT_SPEEDUP=K flies K times
# faster, 3/K at a time (the serial line keeps its baud rate in simulated time).
TCP_SPEEDUP = SERIAL_SPEEDUP = float(os.environ.get("QUADGCS_FAULT_SPEEDUP", "1"))
REALTIME_WORKERS = 3  # flights at once in real time; sped up K times, about 3/K of them


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

    @property
    def lands(self) -> bool:
        """A lost link must end in a landing; a lossy one must keep flying."""
        return self.drop


CASES: dict[str, FaultCase] = {c.name: c for c in (
    FaultCase("downlink", Direction.DOWN, 15.0, True,
              documented="station blind >1 s: requests LAND (uplink works), then goes quiet"),
    FaultCase("uplink", Direction.UP, 15.0, True,
              documented="vehicle hears nothing: its own GCS failsafe lands it"),
    FaultCase("both", Direction.BOTH, 15.0, True,
              documented="LAND requests lost; vehicle's failsafe lands it"),
    FaultCase("lossy", Direction.BOTH, 60.0, False, loss=0.3, bitflip=0.05,
              documented="30 % loss + 5 % flips: any frame is proof of life; keeps holding"),
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
    def gap_throttle_us(self) -> tuple[int, int, float | None] | None:
        """What the station sent once it could no longer see (downlink dead, uplink alive):
        (the highest throttle in the fault's first 0.5 s, the median of the next second, the
        seconds until it released the overrides, None if it never did)."""
        if self.fault_start_s is None or self.case.direction is not Direction.DOWN:
            return None
        t0 = self.fault_start_s
        first = [thr for t, thr in self.overrides if t0 <= t < t0 + 0.5 and thr]
        later = [thr for t, thr in self.overrides if t0 + 0.5 <= t < t0 + 1.5 and thr]
        released = [t - t0 for t, thr in self.overrides if t >= t0 and thr == 0]
        if not first:
            return None
        return (max(first), int(np.median(later)) if later else 0,
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
        """The run in a few lines, for assertion messages and the bench."""
        def f(x: float | None, unit: str) -> str:
            return "none" if x is None else f"{x:.2f}{unit}"
        t0 = self.fault_start_s

        def rel(t: float | None) -> float | None:
            return None if t is None or t0 is None else t - t0

        drift = self.open_loop_drift_m
        return (f"{self.case.name}/{self.profile}/{self.transport} x{self.speedup:g}: exit "
                f"{self.exit_code} ({self.reason!r}); fault at t={f(t0, ' s')}; hold RMS "
                f"before it {f(self.pre_fault_rms_m, ' m')}; max over "
                f"setpoint {f(self.max_over_setpoint_m, ' m')}; touchdown "
                f"{f(rel(self.touchdown_s), ' s')} after the fault at "
                f"{f(self.touchdown_speed_mps, ' m/s')}; disarmed {f(rel(self.disarm_s), ' s')}"
                f" after; LAND seen {f(rel(self.land_mode_s), ' s')} after; failsafe texts "
                f"{[(round(t - (t0 or 0), 1), s) for t, s in self.failsafe_texts]}; open-loop "
                f"{f(self.open_loop_s, ' s')}, drift {drift and tuple(round(d, 3) for d in drift)}"
                f"; last throttle before the fault (us, hold median, ±5-95 %) "
                f"{self.last_throttle_us}; station's throttle blind (max 0-0.5 s, median "
                f"0.5-1.5 s, released after s) {self.gap_throttle_us}; station after the fault "
                f"{self.station_after_fault}"
                f"; hold dev in fault {f(self.hold_during_fault_m, ' m')}; params "
                f"{self.params}; fly's own score {self._score()}; proxy up [{self.up.line()}] "
                f"down [{self.down.line()}]; "
                f"{self.wall_s:.0f} s wall")


# ------------------------------------------------------------------ the run
def _fly_accepts_speedup_with_connect() -> bool:
    """Today's `fly` may refuse `--speedup` with `--connect` (a real vehicle flies in real time);
    then these flights run in real time."""
    done = subprocess.run([sys.executable, "-m", "gcs", "fly", "--connect", "tcp:127.0.0.1:1",
                           "--speedup", "2", "--no-record", "--hold", "1"],
                          capture_output=True, text=True, cwd=ROOT, timeout=60)
    return not (done.returncode == 2 and "real time" in done.stderr)


@functools.cache
def speedup_allowed() -> bool:
    """Asked once per process."""
    return _fly_accepts_speedup_with_connect()


@contextlib.contextmanager
def _sitl(args: list[str]) -> Iterator[Any]:
    from tests.e2e.sitl_proc import SitlProcess

    sitl = SitlProcess(args, cwd=ROOT)
    try:
        yield sitl
    finally:
        sitl.stop()


def fly_with_fault(case: FaultCase, profile: str, transport: str = "tcp",
                   speedup: float = TCP_SPEEDUP, seed: int = 3,
                   record: Path | None = None) -> FlightResult:
    """Fly 1.0 m, start `case` 30 s into the hold, watch until it is over; the result.
    `record`: fly's MCAP recording to this file (default none: it costs the station CPU)."""
    if not speedup_allowed():
        speedup = 1.0
    wall0 = time.monotonic()
    hold_s = FAULT_AFTER_HOLD_S + case.duration_s + (10.0 if case.lands else 8.0)
    udp = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    udp.bind(("127.0.0.1", 0))
    args = ["--tcp", "0", "--profile", profile, "--speedup", f"{speedup:g}", "--seed",
            str(seed), "--udp", f"127.0.0.1:{udp.getsockname()[1]}"]
    if transport == "serial":
        args.append("--serial")
    with contextlib.ExitStack() as stack:
        stack.callback(udp.close)
        sitl = stack.enter_context(_sitl(args))
        watch_udp = MavWatcher(udp, udp=True)
        stack.callback(watch_udp.close)
        mocap_url = next(line.split(" ", 1)[1] for line in sitl.lines
                         if line.startswith("mocap "))
        host, port = mocap_url.removeprefix("tcp:").rsplit(":", 1)
        watch_mocap = MavWatcher(socket.create_connection((host, int(port)), 5.0), udp=False)
        stack.callback(watch_mocap.close)
        tap = StationTap()
        if transport == "serial":
            proxy = FaultProxy(serial_port=sitl.endpoint(1, "serial"), seed=seed,
                               time_scale=speedup, tap=tap)
            connect = f"{proxy.address},115200"
        else:
            h, p = sitl.endpoint(1, "tcp").rsplit(":", 1)
            proxy = FaultProxy(target=(h, int(p)), seed=seed, time_scale=speedup, tap=tap)
            connect = proxy.address
        proxy.start()
        stack.callback(proxy.stop)
        argv = [sys.executable, "-m", "gcs", "fly", "--connect", connect, "--mocap", mocap_url,
                "--profile", profile, "--alt", f"{SETPOINT_M}", "--hold", f"{hold_s:g}",
                "--json", "--live", *(["-o", str(record)] if record else ["--no-record"]),
                # the pilot's consent: the pre-flight checks set FS_GCS_ENABLE/FS_GCS_TIMEOUT
                "--fix-failsafe"]
        if speedup != 1.0:
            argv += ["--speedup", f"{speedup:g}"]
        budget_s = (60.0 + hold_s + case.duration_s) / speedup + 30.0
        run = _run_fly(argv, proxy, case, budget_s)
        # keep watching: the vehicle may still be coming down after fly has given up
        t_fault = run["fault_wall"]
        if t_fault is not None:
            end = t_fault + (case.duration_s + 25.0) / speedup
            while time.monotonic() < end and not _disarmed_after(watch_udp, t_fault):
                time.sleep(0.1)
            time.sleep(min(2.0, max(0.0, end - time.monotonic())))
        params = watch_udp.request_params(("FS_GCS_ENABLE", "FS_GCS_TIMEOUT"), 3.0)
        clock = SimClockMap(watch_mocap.mocap)
        mocap = np.array([(s, h) for _, s, h in watch_mocap.mocap], dtype=float).reshape(-1, 2)
        t_s, up_m = mocap[:, 0], mocap[:, 1]
        # the first second on the floor is the floor: heights in the station's reference
        ground = up_m[t_s <= t_s[0] + 1.0] if t_s.size else up_m
        alt_m = up_m - (float(np.median(ground)) if ground.size else 0.0) + REST_ALT_M
        fault_end = None if t_fault is None else t_fault + case.duration_s / speedup
        return FlightResult(
            case=case, profile=profile, transport=transport, speedup=speedup,
            exit_code=run["code"], stderr=run["stderr"], summary=run["summary"],
            phases=run["phases"], t_s=t_s, alt_m=alt_m,
            fault_start_s=None if t_fault is None else clock(t_fault),
            fault_end_s=None if fault_end is None else clock(fault_end),
            heartbeats=[(clock(w), a, m) for w, a, m in watch_udp.heartbeats],
            texts=[(clock(w), s) for w, s in watch_udp.texts],
            params=params, up=proxy.counters("up"), down=proxy.counters("down"),
            wall_s=time.monotonic() - wall0,
            overrides=[(clock(w), thr) for w, thr in tap.throttle],
            sent=[(clock(w), fate, kind, v) for w, fate, kind, v in tap.sent])


def _disarmed_after(w: MavWatcher, wall: float) -> bool:
    return any(t > wall and not armed for t, armed, _ in w.heartbeats)


def _run_fly(argv: list[str], proxy: FaultProxy, case: FaultCase,
             budget_s: float) -> dict[str, Any]:
    """Run fly; start the fault 30 s into its hold phase (seen on --live); collect output."""
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    proc = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            cwd=ROOT, env=env)
    out: dict[str, Any] = {"phases": [], "fault_wall": None, "summary": None}
    stderr_lines: list[str] = []

    def read_stdout() -> None:
        assert proc.stdout is not None
        last = ""
        for line in proc.stdout:
            word = line.split(" ", 1)[0]
            if line.startswith("{"):
                with contextlib.suppress(json.JSONDecodeError):
                    out["summary"] = json.loads(line)
            elif word and word != last and " alt " in line:
                last = word
                out["phases"].append((time.monotonic(), word))
                if word == "hold" and out["fault_wall"] is None:
                    w = proxy.schedule(case.direction, FAULT_AFTER_HOLD_S, case.duration_s,
                                       drop=case.drop, loss=case.loss, bitflip=case.bitflip)
                    out["fault_wall"] = proxy.monotonic_at(w.start_s)

    readers = [threading.Thread(target=read_stdout, daemon=True),
               threading.Thread(target=lambda: stderr_lines.extend(proc.stderr or []),
                                daemon=True)]
    for r in readers:
        r.start()
    try:
        out["code"] = proc.wait(timeout=budget_s)
    except subprocess.TimeoutExpired:
        proc.terminate()  # fly lands a flying vehicle on SIGTERM before it lets go
        try:
            proc.wait(timeout=15.0)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()
        out["code"] = -1
        stderr_lines.append(f"(fly did not end within {budget_s:.0f} s of wall time)\n")
    for r in readers:
        r.join(5.0)
    out["stderr"] = "".join(stderr_lines)
    if out["fault_wall"] is not None and out["fault_wall"] > time.monotonic():
        out["fault_wall"] = None  # fly ended before the fault began: there was no fault
    return out


@dataclass(frozen=True, slots=True)
class FlightSpec:
    """One flight of the matrix."""

    case: str
    profile: str
    transport: str = "tcp"

    @property
    def id(self) -> str:
        """A short name (pytest ids, the bench's rows)."""
        return f"{self.case}-{self.profile}-{self.transport}"


def run_many(specs: list[FlightSpec], seed: int = 3, speedup: float | None = None,
             record_dir: Path | None = None) -> dict[FlightSpec, FlightResult | Exception]:
    """Fly every spec, longest first, a few at a time: in real time a flight needs about a
    quarter of a core, sped up K times about K quarters. `speedup` None: TCP_SPEEDUP over TCP,
    SERIAL_SPEEDUP over serial, when `fly` allows it. `record_dir`: one MCAP per flight. A
    flight that could not be flown (the SITL would not start, say) is its exception, so the
    others still count."""
    if not specs:
        return {}
    if record_dir is not None:
        record_dir.mkdir(parents=True, exist_ok=True)
    speedup_ok = speedup_allowed() and (speedup or TCP_SPEEDUP) != 1.0

    def one(spec: FlightSpec) -> FlightResult | Exception:
        k = (TCP_SPEEDUP if spec.transport == "tcp" else SERIAL_SPEEDUP) if speedup_ok else 1.0
        if speedup_ok and speedup is not None:
            k = speedup
        try:
            rec = None if record_dir is None else record_dir / f"{spec.id}.mcap"
            return fly_with_fault(CASES[spec.case], spec.profile, spec.transport, k, seed, rec)
        except Exception as exc:  # reported by the caller, per flight
            return exc

    order = sorted(specs, key=lambda s: -CASES[s.case].duration_s)
    k_max = max(speedup or TCP_SPEEDUP, SERIAL_SPEEDUP) if speedup_ok else 1.0
    workers = max(1, round(REALTIME_WORKERS / k_max))
    with concurrent.futures.ThreadPoolExecutor(max_workers=workers) as pool:
        return dict(zip(order, pool.map(one, order), strict=True))
