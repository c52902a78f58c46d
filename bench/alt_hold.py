"""Altitude hold on the bundled SITL: estimators, PC loop vs the autopilot's own ALT_HOLD, timing.

Flights (real time, over TCP, apm25 unless told otherwise):
1. One long hold (`--minutes`, default 5) with the station's default (Kalman) estimator: RMS and
   worst altitude error against ground truth, a 1 m step, the loop's jitter p50/p99, overruns,
   compute and process CPU per tick. Floors: jitter p99 <= 1 ms and 0 overruns.
2. Short holds (`--compare-s`, default 30) with each estimator: the thesis's eq. 6.1 dead
   reckoning, the third-order complementary filter and the Kalman filter, each with a step.
3. The same short hold flown by the autopilot's onboard ALT_HOLD (the station keeps the
   sticks centred, or holds position from motion capture), scored against 1.0 m.
4. Over carpet (`worlds/carpet_room.toml`: echoes up to 1.2 s late or lost), `--carpet N`
   flights of `quadgcs fly --hold 20` at 2x, seeds 1..N: RMS and worst error against truth.
   Issue floor: no divergence, RMS <= 15 cm.
With motion capture (the default world has it) the station also holds the take-off spot.

Prints numbers; asserts nothing.

    .venv/bin/python bench/alt_hold.py [--minutes 5] [--compare-s 30] [--profile apm25]
                                       [--carpet 8]
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import json
import math
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np

from firmware_link import MocapLink, VehicleLink
from firmware_link.records import FlightMode
from gcs.config import EstimatorKind, StationConfig
from gcs.errors import QuadgcsError
from gcs.flight import FlightPlan, FlightRunner, Phase
from gcs.sitl_process import SitlOptions, SitlProcess
from gcs.station import Station
from gcs.thrust_curve import ThrottleCurve


@contextlib.contextmanager
def session(profile: str, config: StationConfig, seed: int) -> Iterator[Station]:
    """A bundled SITL, a link to it and a started station; all stopped on exit."""
    with contextlib.ExitStack() as stack:
        sitl = SitlProcess(SitlOptions(profile=profile, seed=seed))
        endpoints = sitl.start()
        url = endpoints.url(1)
        stack.callback(sitl.stop)
        mocap = None
        if endpoints.mocap is not None:
            mocap = MocapLink.open(endpoints.mocap)
            stack.callback(mocap.close)
        link = VehicleLink.open(url)
        stack.callback(link.close)
        link.bring_up(40.0)
        names = ("MOT_THST_HOVER",) if profile == "copter4" else ("THR_MIN", "THR_MID")
        params = {n: link.get_param(n) for n in names}
        st = Station(link, config=config, curve=ThrottleCurve.for_dialect(link.dialect, params),
                     mocap=mocap)
        st.start()
        stack.callback(st.stop)
        yield st


def pc_flight(profile: str, kind: EstimatorKind, hold_s: float, seed: int) -> dict[str, float]:
    """Fly the PC loop with one estimator; the summary's numbers plus CPU per tick."""
    config = dataclasses.replace(StationConfig(), estimator_kind=kind)
    with session(profile, config, seed) as st:
        runner = FlightRunner(st, FlightPlan(alt_m=1.0, hold_s=hold_s, step_m=1.0))
        cpu0, ticks0 = time.process_time(), st.snapshot().loop.ticks
        runner.fly()
        cpu1, snap = time.process_time(), st.snapshot()
        s = runner.summary()
    step = s.step
    return {
        "rms_cm": s.rms_error_m * 100,
        "max_cm": s.max_error_m * 100,
        "overshoot_pct": step.overshoot_pct if step else math.nan,
        "settle_s": step.settle_time_s if step else math.nan,
        "jitter_p50_ms": s.jitter_p50_ms,
        "jitter_p99_ms": s.jitter_p99_ms,
        "overruns": s.overruns,
        "compute_p50_ms": snap.loop.compute_p50_s * 1e3,
        "compute_p99_ms": s.compute_p99_ms,
        "cpu_per_tick_ms": (cpu1 - cpu0) / max(1, snap.loop.ticks - ticks0) * 1e3,
    }


def onboard_flight(profile: str, hold_s: float, seed: int) -> dict[str, float]:
    """Take off under the PC loop, then hand over to the autopilot's ALT_HOLD and score it."""
    with session(profile, StationConfig(), seed) as st:
        runner = FlightRunner(st, FlightPlan(alt_m=1.0, hold_s=0.1, settle_s=4.0))
        runner.arm()
        runner.phase = Phase.TAKEOFF
        st.alt_hold(True, 1.0, rate_mps=0.5)
        runner.wait("take-off", lambda s: s.estimate is not None
                     and abs(s.estimate.alt_m - 1.0) < 0.05, 20.0)
        runner.pause(4.0)
        # centred sticks: mid throttle is "hold this altitude" in ALT_HOLD
        st.set_sticks(1500, 1500, 1500, 1500)
        st.alt_hold(False)
        runner.expected_modes.add(FlightMode.ALT_HOLD)
        st.set_mode(FlightMode.ALT_HOLD)
        runner.wait("ALT_HOLD", lambda s: s.vehicle_mode == FlightMode.ALT_HOLD, 5.0)
        runner.pause(2.0)  # the handover transient is not the hold
        runner.phase = Phase.HOLD
        t0 = st.clock.now_s()
        runner.pause(hold_s)
        origin = runner.truth_origin_m() or 0.0
        alts = np.array([s.truth_alt_m - origin for s in runner.samples
                         if s.phase is Phase.HOLD and s.t_s >= t0 and s.truth_alt_m is not None])
        # back to STABILIZE under the PC loop (bumpless from the centred stick), then land
        st.set_mode(FlightMode.STABILIZE)
        runner.wait("STABILIZE", lambda s: s.vehicle_mode == FlightMode.STABILIZE, 5.0)
        st.alt_hold(True)
        runner.land()
    err = alts - 1.0
    drift = alts - alts.mean()
    return {"rms_cm": float(np.sqrt(np.mean(err**2))) * 100,
            "max_cm": float(np.max(np.abs(err))) * 100,
            "rms_about_mean_cm": float(np.sqrt(np.mean(drift**2))) * 100,
            "mean_alt_m": float(alts.mean())}


CARPET_WORLD = Path(__file__).resolve().parents[1] / "worlds" / "carpet_room.toml"


def carpet_flight(profile: str, seed: int) -> dict[str, float]:
    """One `quadgcs fly` over carpet, through the real CLI; its JSON summary."""
    cmd = [sys.executable, "-m", "gcs", "fly", "--no-record", "--json", "--profile", profile,
           "--world", str(CARPET_WORLD), "--seed", str(seed), "--alt", "1.0", "--hold", "20",
           "--speedup", "2"]
    done = subprocess.run(cmd, capture_output=True, text=True, timeout=300, check=False)
    if done.returncode != 0:
        lines = (done.stderr or done.stdout).strip().splitlines() or ["no output"]
        raise QuadgcsError(f"carpet flight, seed {seed}: {lines[-1]}")
    summary: dict[str, float] = json.loads(done.stdout)
    return summary


def main(argv: list[str] | None = None) -> int:
    """Run the flights and print a table."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--minutes", type=float, default=5.0, help="long hold, minutes")
    ap.add_argument("--compare-s", type=float, default=30.0, help="short holds, seconds")
    ap.add_argument("--profile", choices=("apm25", "copter4"), default="apm25")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--carpet", type=int, default=8, metavar="N", help="flights over carpet")
    args = ap.parse_args(argv)
    print(f"bench/alt_hold.py  profile={args.profile} seed={args.seed}")
    try:
        r = pc_flight(args.profile, EstimatorKind.KALMAN, args.minutes * 60.0, args.seed)
        print(f"\n[1] PC loop, Kalman estimator, {args.minutes:g} min hold at 1.0 m")
        print(f"    altitude error vs truth: RMS {r['rms_cm']:.2f} cm, worst {r['max_cm']:.2f} cm")
        print(f"    1 m step: overshoot {r['overshoot_pct']:.1f} %, settled (±5 cm) after "
              f"{r['settle_s']:.2f} s")
        print(f"    loop jitter p50 {r['jitter_p50_ms']:.3f} ms, p99 {r['jitter_p99_ms']:.3f} ms "
              f"(floor 1 ms); overruns {r['overruns']} (floor 0)")
        print(f"    compute per tick p50 {r['compute_p50_ms']:.3f} ms, p99 "
              f"{r['compute_p99_ms']:.3f} ms; process CPU {r['cpu_per_tick_ms']:.3f} ms/tick")
        print(f"\n[2] estimators, {args.compare_s:g} s hold + 1 m step each")
        print(f"    {'estimator':16s} {'RMS cm':>8s} {'worst cm':>9s} {'overshoot %':>12s} "
              f"{'settle s':>9s} {'CPU ms/tick':>12s}")
        for kind in (EstimatorKind.DEAD_RECKONING, EstimatorKind.COMPLEMENTARY,
                     EstimatorKind.KALMAN):
            try:
                e = pc_flight(args.profile, kind, args.compare_s, args.seed)
                print(f"    {kind.value:16s} {e['rms_cm']:8.2f} {e['max_cm']:9.2f} "
                      f"{e['overshoot_pct']:12.1f} {e['settle_s']:9.2f} "
                      f"{e['cpu_per_tick_ms']:12.3f}")
            except QuadgcsError as exc:
                print(f"    {kind.value:16s} flight failed: {exc}")
        o = onboard_flight(args.profile, args.compare_s, args.seed)
        print(f"\n[3] autopilot's onboard ALT_HOLD, {args.compare_s:g} s from 1.0 m")
        print(f"    altitude error vs 1.0 m: RMS {o['rms_cm']:.2f} cm, worst {o['max_cm']:.2f} cm "
              f"(held {o['mean_alt_m']:.3f} m on average, {o['rms_about_mean_cm']:.2f} cm RMS "
              f"about it)")
        if args.carpet > 0:
            print(f"\n[4] over carpet, {args.carpet} flights of 20 s at 1.0 m (2x), seeds "
                  f"1..{args.carpet}")
            rms, worst = [], []
            for seed in range(1, args.carpet + 1):
                c = carpet_flight(args.profile, seed)
                rms.append(c["rms_error_m"] * 100)
                worst.append(c["max_error_m"] * 100)
                print(f"    seed {seed:2d}: RMS {rms[-1]:6.2f} cm, worst {worst[-1]:6.2f} cm")
            print(f"    RMS {min(rms):.2f}-{max(rms):.2f} cm (median {np.median(rms):.2f}); worst "
                  f"{max(worst):.2f} cm (floor: RMS <= 15 cm, no divergence)")
    except QuadgcsError as exc:
        print(f"bench/alt_hold.py: {exc}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
