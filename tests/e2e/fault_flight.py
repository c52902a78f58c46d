"""One `quadgcs fly` through the fault proxy, watched from outside the link it breaks.

The SITL runs as its own program; the station is the real CLI (`python -m gcs fly --connect
<proxy> --json --live`), so what is tested is what a user runs. The fault hits only the vehicle
link. Height comes from the motion-capture endpoint (which the fault does not touch), and the
vehicle's arming state, mode and texts from a UDP endpoint of the SITL that only listens (it
never sends a heartbeat, so it cannot keep the vehicle's GCS failsafe from firing).

Times are the SITL's simulated seconds (mocap `time_usec`); what is stamped on the wall clock
(heartbeats, the fault window) is mapped through the mocap stream's arrival times. The cases
and the numbers judged from a flight are in tests/e2e/fault_result.py, the watchers in
tests/e2e/fault_watch.py.
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

from sitl.fault_proxy import FaultProxy
from tests.e2e.fault_result import CASES, REST_ALT_M, SETPOINT_M, FaultCase, FlightResult
from tests.e2e.fault_watch import MavWatcher, SimClockMap, StationTap

ROOT = Path(__file__).resolve().parents[2]
FAULT_AFTER_HOLD_S = 30.0
# Real time, three flights at a time, by default: on a shared two-core machine, two 2x flights
# at a time lost their hold before any fault in 5 of 18 flights (RMS 0.07 to 1.43 m over the
# 10 s before it); all 9 real-time flights held within 0.03 m. QUADGCS_FAULT_SPEEDUP=K flies K times
# faster, 3/K at a time (the serial line keeps its baud rate in simulated time).
TCP_SPEEDUP = SERIAL_SPEEDUP = float(os.environ.get("QUADGCS_FAULT_SPEEDUP", "1"))
REALTIME_WORKERS = 3  # flights at once in real time; sped up K times, about 3/K of them


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
                   record: Path | None = None,
                   after_hold_s: float = FAULT_AFTER_HOLD_S) -> FlightResult:
    """Fly 1.0 m, start `case` `after_hold_s` (30 s) into the hold, watch until it is over;
    the result.
    `record`: fly's MCAP recording to this file (default none: it costs the station CPU)."""
    if not speedup_allowed():
        speedup = 1.0
    wall0 = time.monotonic()
    hold_s = after_hold_s + case.duration_s + (10.0 if case.lands else 8.0)
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
        run = _run_fly(argv, proxy, case, budget_s, after_hold_s)
        # keep watching: the vehicle may still be coming down after fly has given up
        t_fault = run["fault_wall"]
        if t_fault is not None:
            end = t_fault + (case.duration_s + 25.0) / speedup
            watch_udp.wait_until(lambda w: _disarmed_after(w, t_fault),
                                 end - time.monotonic())
            # two more seconds of motion capture after the disarm: the touchdown's samples
            until = min(time.monotonic() + 2.0, end)
            watch_mocap.wait_until(lambda w: bool(w.mocap) and w.mocap[-1][0] >= until,
                                   end - time.monotonic())
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
             budget_s: float, after_hold_s: float) -> dict[str, Any]:
    """Run fly; start the fault `after_hold_s` into its hold phase (seen on --live); collect
    output."""
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
                    w = proxy.schedule(case.direction, after_hold_s, case.duration_s,
                                       drop=case.drop, loss=case.loss, bitflip=case.bitflip)
                    fault_wall = proxy.monotonic_at(w.start_s)
                    out["fault_wall"] = fault_wall
                    if case.kill:
                        threading.Timer(max(0.0, fault_wall - time.monotonic()),
                                        proc.kill).start()

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
             record_dir: Path | None = None, after_hold_s: float = FAULT_AFTER_HOLD_S,
             ) -> dict[FlightSpec, FlightResult | Exception]:
    """Fly every spec, longest first, a few at a time: in real time a flight needs about a
    quarter of a core, sped up K times about K quarters. `speedup` None: TCP_SPEEDUP over TCP,
    SERIAL_SPEEDUP over serial, when `fly` allows it. `record_dir`: fly's MCAP and the watched
    series (.npz) per flight. A
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
            r = fly_with_fault(CASES[spec.case], spec.profile, spec.transport, k, seed, rec,
                               after_hold_s)
            if rec is not None:
                r.save(rec.with_suffix(".npz"))
            return r
        except Exception as exc:  # reported by the caller, per flight
            return exc

    order = sorted(specs, key=lambda s: -CASES[s.case].duration_s)
    k_max = max(speedup or TCP_SPEEDUP, SERIAL_SPEEDUP) if speedup_ok else 1.0
    workers = max(1, round(REALTIME_WORKERS / k_max))
    with concurrent.futures.ThreadPoolExecutor(max_workers=workers) as pool:
        return dict(zip(order, pool.map(one, order), strict=True))
