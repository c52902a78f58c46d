"""Telemetry bursts: what late, bunched samples cost the altitude estimate and the hold.

1. Synthetic (the estimator alone, seeded): a 1 m climb and descent at up to 1 m/s, IMU at
   40 Hz, sonar at 20 Hz. From 5 s on, every 0.5 s the link either goes silent for 0.2 s and
   then delivers it all at once ("silence": a starved SITL), or falls 0.2 s behind for a
   quarter second and catches up in one tick ("lag"). Error against truth from 7 s on, with
   each sample integrated at its own time (the station) and with each tick's samples averaged
   into one (how the station took them before).
2. The bundled SITL over TCP at 2x, stopped (SIGSTOP) for `--stop` of every `--every` wall
   seconds: `quadgcs fly --connect` with a 10 s hold at 1 m and a 1 m step (watched 12 s,
   settled within ±10 cm), per profile and seed, scored against the SITL's ground truth.
3. The same stall in lockstep (`sitl.lockstep.Stall`: twice `--stop` of every twice
   `--every` simulated seconds), where it falls at the same moments for every run of a seed:
   the spread over many seeds that the wall-clock flights of 2. sample a few points of, the
   settling within ±10 cm and within the usual ±5 cm.

Prints numbers; asserts nothing.

    .venv/bin/python bench/bursts.py [--seeds 8] [--flights 3] [--stop 0.15] [--every 0.3]
                                     [--lockstep-seeds 30]
"""

from __future__ import annotations

import argparse
import contextlib
import io
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from gcs.cli import build_parser  # noqa: E402
from gcs.commands.fly import fly  # noqa: E402
from lab.lockstep import install  # noqa: E402
from tests.e2e.sitl_proc import SitlProcess, starved  # noqa: E402
from tests.gcs.test_estimation_bursts import fly_bursts  # noqa: E402
from tests.gcs.test_stalled_sitl import fly_stalled  # noqa: E402


def synthetic(seeds: int) -> None:
    print(f"1. synthetic climb, seeds 1-{seeds}: error vs truth from 7 s (cm)")
    for pattern in ("silence", "lag"):
        for averaged, label in ((False, "each sample at its time"), (True, "averaged per tick")):
            runs = [fly_bursts(pattern, s, averaged=averaged)[0] for s in range(1, seeds + 1)]
            rms = [float(np.sqrt(np.mean(e**2))) * 100 for e in runs]
            worst = [float(np.max(np.abs(e))) * 100 for e in runs]
            print(f"   {pattern:7s} {label:24s} RMS median {np.median(rms):5.2f}, worst "
                  f"{max(rms):5.2f}; max error median {np.median(worst):5.1f}, worst "
                  f"{max(worst):5.1f}")


def starved_flight(profile: str, seed: int, stop_s: float, every_s: float) -> dict:
    sitl = SitlProcess(["--tcp", "0", "--speedup", "2", "--seed", str(seed),
                        "--profile", profile, "--mocap-port", "0"], ROOT)
    try:
        args = build_parser().parse_args([
            "fly", "--no-record", "--fix-failsafe", "--connect", "tcp:" + sitl.endpoint(1, "tcp"),
            "--mocap", sitl.mocap_url(), "--alt", "1.0", "--hold", "10", "--step", "1.0",
            "--step-watch", "12", "--step-band", "0.1", "--speedup", "2"])
        with starved(sitl.proc, stop_s, every_s), contextlib.redirect_stdout(io.StringIO()):
            return fly(args)
    finally:
        sitl.stop()


def flights(n: int, stop_s: float, every_s: float) -> None:
    print(f"2. SITL over TCP at 2x, stopped {stop_s} s of every {every_s} s (wall), seeds 1-{n}")
    for profile in ("apm25", "copter4"):
        for seed in range(1, n + 1):
            s = starved_flight(profile, seed, stop_s, every_s)
            step = s.get("step") or {}
            settle = step.get("settle_time_s")
            print(f"   {profile:7s} seed {seed}: {s['status']}, hold RMS "
                  f"{(s.get('rms_error_m') or float('nan')) * 100:.1f} cm, max "
                  f"{(s.get('max_error_m') or float('nan')) * 100:.1f} cm "
                  f"({s.get('error_source')}); step overshoot "
                  f"{step.get('overshoot_pct', float('nan')):.1f} %, settled within +-10 cm "
                  f"{'never' if settle is None else f'in {settle:.2f} s'}")


def lockstep(n: int, stop_s: float, every_s: float) -> None:
    print(f"3. lockstep, stalled {stop_s} s of every {every_s} s (simulated), 1 m step watched "
          f"12 s, seeds 1-{n}")
    for profile in ("apm25", "copter4"):
        for band_m in (0.1, 0.05):
            runs = [fly_stalled(profile, seed, stop_s, every_s, band_m)
                    for seed in range(1, n + 1)]
            ok = [r for r in runs if r["status"] == "ok"]
            rms = [100 * r["rms_error_m"] for r in ok]
            over = [r["step"]["overshoot_pct"] for r in ok]
            times = [t for r in ok if (t := r["step"]["settle_time_s"]) is not None]
            settled = (f"in {min(times):.2f}-{max(times):.2f} s (median {np.median(times):.2f})"
                       if times else "")
            print(f"   {profile:7s} {len(ok)}/{n} ok; hold RMS median {np.median(rms):.1f}, "
                  f"worst {max(rms):.1f} cm; overshoot median {np.median(over):.1f}, range "
                  f"{min(over):.1f}-{max(over):.1f} %; within +-{100 * band_m:.0f} cm settled "
                  f"{len(times)}/{len(ok)} {settled}")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=8, help="synthetic flights per pattern")
    ap.add_argument("--flights", type=int, default=3, help="SITL flights per profile")
    ap.add_argument("--stop", type=float, default=0.15, help="wall seconds stopped")
    ap.add_argument("--every", type=float, default=0.3, help="wall seconds between stops")
    ap.add_argument("--lockstep-seeds", type=int, default=30,
                    help="lockstep flights per profile (the stall at 2x: twice --stop, --every)")
    a = ap.parse_args()
    if not 0.0 < a.stop < a.every:
        ap.error("need 0 < --stop < --every")
    synthetic(a.seeds)
    flights(a.flights, a.stop, a.every)
    if a.lockstep_seeds:
        lockstep(a.lockstep_seeds, 2 * a.stop, 2 * a.every)
    return 0


if __name__ == "__main__":
    install()  # lockstep flights fly the bundled SITL in this process
    raise SystemExit(main())
