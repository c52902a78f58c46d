"""A lossy link under a hold, over many seeds: how far the vehicle strays from the setpoint.

Flies `quadgcs fly` (1.0 m) in lockstep on the bundled SITL with the vehicle's link losing
each frame, both ways, with probability 0.335 from t = 40 s (simulated, about 30 s into the
hold) for 60 s: the fault suite's 30 % loss with 5 % bit flips, whose flipped frames fail
their checksum and are lost to the station as well (1 - 0.7 x 0.95). Heights are the SITL's
truth, which the fault does not touch.

Prints per profile: the worst deviation from the setpoint during the loss (median, worst,
flights over 0.1 m), the hold's RMS over the same seconds, the flights that ended early.

    .venv/bin/python bench/lossy_hold.py [--seeds 1-60] [--profiles apm25,copter4]
"""

from __future__ import annotations

import argparse
import statistics
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from bench.open_loop import seed_range
from gcs.commands.fly import fly_session
from gcs.errors import FlightFailed
from gcs.flight import FlightPlan
from gcs.lockstep_session import LockstepSession
from gcs.station.session import SessionOptions
from lab.lockstep import install

LOSS = 1.0 - 0.7 * 0.95
LOSS_START_S = 40.0
LOSS_S = 60.0
SETPOINT_M = 1.0
HOLD_M = 0.1
HOLD_S = 95.0  # the hold begins about 15 s in, so it outlasts the loss


def fly_lossy(profile: str, seed: int) -> tuple[float, float, str]:
    """(worst |height - setpoint| during the loss, RMS over it, how the flight ended)."""
    options = SessionOptions(command="fly", profile=profile, seed=seed, record=False,
                             fix_failsafe=True)
    faults = {"loss": LOSS, "loss_start_s": LOSS_START_S, "loss_s": LOSS_S}
    ended = "ok"
    with LockstepSession(options, faults=faults) as session:
        try:
            fly_session(session, FlightPlan(alt_m=SETPOINT_M, hold_s=HOLD_S),
                        pilot_signals=False)
        except FlightFailed as exc:
            ended = str(exc)
        series = session.first.truth_series()
    assert series is not None, "lockstep flies with the truth endpoint"
    t, alt = series.t_s, series.alt_m  # the station's floor reference, as its setpoint
    sel = (t >= LOSS_START_S) & (t < LOSS_START_S + LOSS_S)
    err = alt[sel] - SETPOINT_M
    if not err.size:
        return float("nan"), float("nan"), ended
    return float(np.abs(err).max()), float(np.sqrt(np.mean(err**2))), ended


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", default="1-60", help="SITL seeds, FIRST-LAST (default 1-60)")
    ap.add_argument("--profiles", default="apm25,copter4", help="comma-separated profiles")
    ap.add_argument("--verbose", action="store_true", help="a line per flight")
    args = ap.parse_args()
    seeds = seed_range(args.seeds)
    print(f"lockstep, 1.0 m hold, frame loss {LOSS:.3f} both ways from t = {LOSS_START_S:g} s "
          f"for {LOSS_S:g} s, seeds {seeds[0]}-{seeds[-1]}, truth heights")
    print(f"{'profile':8} {'worst |err| m med/max':>22} {'> 0.1 m':>7} {'RMS cm med/max':>15} "
          f"{'ended early':>11}")
    for profile in args.profiles.split(","):
        runs = []
        for s in seeds:
            worst, rms, ended = fly_lossy(profile, s)
            runs.append((worst, rms, ended))
            if args.verbose:
                print(f"  {profile} seed {s}: worst {worst:.3f} m, RMS {100 * rms:.1f} cm, "
                      f"{ended}", flush=True)
        worsts = [w for w, _, _ in runs]
        rmss = [r for _, r, _ in runs]
        print(f"{profile:8} {statistics.median(worsts):10.3f} / {max(worsts):.3f} "
              f"{sum(w > HOLD_M for w in worsts):7d} {100 * statistics.median(rmss):7.1f} / "
              f"{100 * max(rmss):.1f} {sum(e != 'ok' for _, _, e in runs):11d}", flush=True)
    return 0


if __name__ == "__main__":
    install()  # lockstep flights fly the bundled SITL in this process
    sys.exit(main())
