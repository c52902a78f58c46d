"""Link faults on the bundled SITL: what `quadgcs fly` does when the link dies or turns lossy.

The flights of tests/e2e/test_faults.py, with the numbers instead of the asserts: the SITL, the
fault proxy (sitl.fault_proxy) between it and the station, and the real CLI `quadgcs fly
--connect <proxy> --mocap <sitl mocap> --json`, holding 1.0 m; 30 s into the hold the fault
starts. Height from motion capture (untouched by the fault), arming and mode from a listen-only
UDP endpoint of the SITL.

Faults: downlink lost 15 s; uplink lost 15 s; both ways lost 15 s; 30 % frame loss with 5 %
bit flips both ways for 60 s; the station's process SIGKILLed (its guardian,
gcs/station/guardian.py, takes the link over). `--serial` adds both-ways loss over the
115200-baud pty (apm25).

Columns: fault | profile | documented response | max height over setpoint | touchdown speed
(vertical, just before contact) | time from the fault to disarm | fly's exit code; then the
open-loop seconds (uplink dead, before the vehicle's own failsafe acts) and their drift, and
the worst hold error during a lossy fault; what the station sent once blind (its LAND requests,
when it released the overrides, its last frame; read off the uplink by a proxy tap) and the
throttle the vehicle was left with.

Prints numbers; asserts nothing.

    .venv/bin/python bench/faults.py [--speedup K] [--profile apm25|copter4|both]
                                     [--case downlink ...] [--serial] [--seed N]
                                     [--repeat N] [--record DIR]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

# The flights are the e2e suite's own (tests/e2e/fault_flight.py); `quadgcs bench` runs this
# file with -P, so the source tree is put on the path to import them.
ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from tests.e2e.fault_flight import (  # noqa: E402
    CASES,
    FlightResult,
    FlightSpec,
    run_many,
    speedup_allowed,
)


def _num(x: float | None, fmt: str) -> str:
    return "-" if x is None else format(x, fmt)


def row(r: FlightResult) -> str:
    """One table row."""
    t0 = r.fault_start_s
    disarm = None if r.disarm_s is None or t0 is None else r.disarm_s - t0
    speed = r.touchdown_speed_mps if r.case.lands else None
    return (f"{r.case.name + ('/serial' if r.transport == 'serial' else ''):15s} "
            f"{r.profile:8s} {r.case.documented:66s} {r.max_over_setpoint_m:+9.3f} "
            f"{_num(speed, '9.2f'):>9s} {_num(disarm, '9.1f'):>9s} {r.exit_code:5d}")


def details(r: FlightResult) -> str:
    """The second line: open-loop drift, the lossy hold, the stderr reason."""
    parts = [f"highest {_num(r.max_over_at_s, '+.1f')} s after the fault"]
    if r.open_loop_s is not None and r.open_loop_drift_m is not None:
        change, widest = r.open_loop_drift_m
        fs = ", ".join(s for _, s in r.failsafe_texts[:2]) or "LAND seen"
        parts.append(f"open loop {r.open_loop_s:.1f} s (drift {change:+.3f} m, widest "
                     f"{widest:.3f} m) until the vehicle's failsafe ({fs})")
    sent = r.station_after_fault
    if sent is not None and r.case.lands:
        parts.append(f"station: LAND asked at {sent['land_requests_s']} s, overrides released "
                     f"at {sent['released_s']} s, last frame at {sent['last_frame_s']} s")
    gap = r.gap_throttle_us
    if gap is not None:
        parts.append(f"blind throttle: {gap[0]}..{gap[1]} us in the first 0.5 s, then {gap[2]} us "
                     f"(hold median before {r.last_throttle_us[1] if r.last_throttle_us else '-'}"
                     " us)")
    elif r.open_loop_s is not None and r.last_throttle_us is not None:
        last, mid, band = r.last_throttle_us
        parts.append(f"left with {last} us (hold median {mid:.0f} ± {band:.0f} us)")
    if not r.case.lands and r.hold_during_fault_m is not None:
        parts.append(f"worst hold error in the fault {r.hold_during_fault_m * 100:.1f} cm; "
                     f"corrupted up/down {r.up.frames_corrupted}/{r.down.frames_corrupted}")
    if r.params:
        parts.append("params " + ", ".join(f"{k} {v:g}" for k, v in r.params.items()))
    if r.fault_start_s is None:
        parts.append("the fault never started")
    parts.append(f"fly: {r.reason or 'no stderr'}")
    return "    " + "; ".join(parts)


def main(argv: list[str] | None = None) -> int:
    """Fly the faults and print the table."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--speedup", type=float, default=None, metavar="K",
                    help="SITL, proxy and station K times faster (default 4 over TCP, 2 over "
                         "serial; real time when fly refuses --speedup with --connect)")
    ap.add_argument("--profile", choices=("apm25", "copter4", "both"), default="both",
                    help="firmware profile(s) to fly (default both)")
    ap.add_argument("--case", choices=sorted(CASES), action="append", default=None,
                    help="fault(s) to fly (default all; repeatable)")
    ap.add_argument("--serial", action="store_true",
                    help="also fly both-ways loss over the serial pty (apm25)")
    ap.add_argument("--seed", type=int, default=3, help="SITL noise and fault seed (default 3)")
    ap.add_argument("--repeat", type=int, default=1, metavar="N",
                    help="fly every case N times, seeds SEED..SEED+N-1: where the outcome "
                         "hangs on the last command the vehicle got, one flight is one draw")
    ap.add_argument("--record", type=Path, metavar="DIR",
                    help="keep fly's MCAP recording of each flight in DIR (default none)")
    args = ap.parse_args(argv)
    if args.speedup is not None and not 0 < args.speedup <= 50:
        print(f"bench/faults.py: --speedup {args.speedup}: expected 0 < K <= 50",
              file=sys.stderr)
        return 2
    if args.repeat < 1:
        print(f"bench/faults.py: --repeat {args.repeat}: expected N >= 1", file=sys.stderr)
        return 2
    profiles = ("apm25", "copter4") if args.profile == "both" else (args.profile,)
    specs = [FlightSpec(c, p) for c in (args.case or list(CASES)) for p in profiles]
    if args.serial:
        specs.append(FlightSpec("both", "apm25", "serial"))
    note = "" if speedup_allowed() else (" (fly refuses --speedup with --connect: real time, "
                                         "three flights at a time)")
    seeds = range(args.seed, args.seed + args.repeat)
    print(f"bench/faults.py  seeds={list(seeds)} flights={len(specs) * args.repeat}{note}",
          flush=True)
    t0 = time.monotonic()
    results = {seed: run_many(specs, seed=seed, speedup=args.speedup,
                              record_dir=None if args.record is None
                              else args.record / f"seed{seed}")
               for seed in seeds}
    print(f"\n{'fault':15s} {'profile':8s} {'documented response':66s} {'over set':>9s} "
          f"{'touch m/s':>9s} {'disarm s':>9s} {'exit':>5s}")
    speeds = set()
    for spec in specs:
        for seed in seeds:
            r = results[seed][spec]
            if isinstance(r, Exception):
                print(f"{spec.case:15s} {spec.profile:8s} not flown: {type(r).__name__}: {r}")
                continue
            speeds.add(f"{r.speedup:g}x")
            print(row(r) + (f"  seed {seed}" if args.repeat > 1 else ""))
            print(details(r))
    print(f"\n{len(specs) * args.repeat} flights at {', '.join(sorted(speeds))} in "
          f"{time.monotonic() - t0:.0f} s of wall time; heights from motion capture, 'over set'"
          " = highest height - 1.0 m")
    return 0


if __name__ == "__main__":
    sys.exit(main())
