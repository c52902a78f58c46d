"""The firmware's open-loop seconds over many seeds: a radio fade in lockstep, what it does.

Flies `quadgcs fly` (1.0 m, 45 s hold) in lockstep on the bundled SITL with a fade of the
vehicle's link from t = 40 s (simulated, a little over 30 s into the hold) for 15 s: the uplink
only, or both ways. With the uplink dead the autopilot flies the last override until its own
failsafe (3.2.1: radio failsafe 2 s after the last override; 4.x: GCS failsafe after
FS_GCS_TIMEOUT 2 s), then lands. Heights are the SITL's truth; the SITL runs on 25 s after the
station has given up, so the landing is seen.

Prints per profile and fade: the peak height (median, worst, flights above setpoint + 0.3 m)
the touchdown speed (median, worst, flights over 1.0 m/s: the slope of the last 0.25 s above the
floor), the flights that never came down, and when the autopilot disarmed, counted from the
fade's start (median, worst; its land detector, 0.1 s steps).

    .venv/bin/python bench/open_loop.py [--seeds 1-60] [--fade up,both]
"""

from __future__ import annotations

import argparse
import contextlib
import statistics
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from gcs.commands.fly import fly_session
from gcs.errors import FlightFailed
from gcs.flight import FlightPlan
from gcs.lockstep_session import LockstepSession
from gcs.station.session import SessionOptions
from lab.lockstep import install

FADE_START_S = 40.0
FADE_S = 15.0
SETPOINT_M = 1.0
AFTER_S = 25.0
FLOOR_BAND_M = 0.03
HELD_S = 10.0  # the hold's level: the median truth height over this long before the fade


def fly_fade(profile: str, fade: str, seed: int) -> tuple[float, float | None, float | None]:
    """(peak height after the fade began, on the setpoint's scale, touchdown speed or None,
    seconds from the fade's start to the autopilot's disarm or None)."""
    options = SessionOptions(command="fly", profile=profile, seed=seed, record=False,
                             fix_failsafe=True)
    faults = {"fade": fade, "fade_start_s": FADE_START_S, "fade_s": FADE_S}
    session = LockstepSession(options, faults=faults)
    with session:
        vehicle = session.first
        # the flight fails when the vehicle leaves the station's control: what follows is the
        # point
        with contextlib.suppress(FlightFailed):
            fly_session(session, FlightPlan(alt_m=SETPOINT_M, hold_s=45.0), pilot_signals=False)
        state = session.sitl.sitl.sim.vehicle(1).autopilot.state
        disarmed = None if state.armed else session.clock.now_s() - FADE_START_S
        end = session.clock.now_s() + AFTER_S
        while session.clock.now_s() < end and vehicle.truth is not None:
            session.sitl.sitl.advance_to(session.clock.now_s() + 0.1)
            vehicle.truth.reports()  # takes what arrived (nothing pumps it once fly is over)
            if disarmed is None and not state.armed:
                disarmed = session.clock.now_s() - FADE_START_S
        series = vehicle.truth_series()
    assert series is not None, "lockstep flies with the truth endpoint"
    t, alt = series.t_s, series.alt_m
    floor = float(alt[: max(1, min(50, alt.size))].min())
    after = t >= FADE_START_S
    # heights from the level the hold kept before the fade, not from the floor: above the
    # truth's resting height the hold sits a few cm under its setpoint (0.93-0.95 m for 1.0 m),
    # which a peak counted from the floor would take as headroom
    held = float(np.median(alt[(t >= FADE_START_S - HELD_S) & ~after]))
    peak = SETPOINT_M + float(alt[after].max()) - held
    down = np.nonzero(after & (alt <= floor + FLOOR_BAND_M))[0]
    if not down.size:
        return peak, None, disarmed
    t_c = t[down[0]]
    sel = (t >= t_c - 0.25) & (t <= t_c)
    return peak, float(max(0.0, -np.polyfit(t[sel] - t_c, alt[sel], 1)[0])), disarmed


def seed_range(text: str) -> list[int]:
    """FIRST-LAST (or one seed) as the list of seeds."""
    first, _, last = text.partition("-")
    return list(range(int(first), int(last or first) + 1))


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", default="1-60", help="SITL seeds, FIRST-LAST (default 1-60)")
    ap.add_argument("--fade", default="up,both", help="fades: up, both, down (comma-separated)")
    args = ap.parse_args()
    seeds = seed_range(args.seeds)
    print(f"lockstep, 1.0 m hold, {FADE_S:g} s fade from t = {FADE_START_S:g} s, seeds "
          f"{seeds[0]}-{seeds[-1]}, truth heights")
    print(f"{'profile':8} {'fade':5} {'peak m med/max':>15} {'> +0.3 m':>8} "
          f"{'touch m/s med/max':>18} {'> 1 m/s':>7} {'not down':>8} {'disarm s med/max':>17}")
    for profile in ("apm25", "copter4"):
        for fade in args.fade.split(","):
            runs = [fly_fade(profile, fade, s) for s in seeds]
            peaks = [p for p, _, _ in runs]
            speeds = [v for _, v, _ in runs if v is not None]
            offs = [d for _, _, d in runs if d is not None]
            off = (f"{statistics.median(offs):.1f} / {max(offs):.1f}" if offs else "-")
            off += "" if len(offs) == len(runs) else f" ({len(runs) - len(offs)} armed)"
            high = sum(p > SETPOINT_M + 0.3 for p in peaks)
            fast = sum(v > 1.0 for v in speeds)
            touch = (f"{statistics.median(speeds):.2f} / {max(speeds):.2f}" if speeds else "-")
            print(f"{profile:8} {fade:5} {statistics.median(peaks):7.2f} / {max(peaks):4.2f} "
                  f"{high:8d} {touch:>18} {fast:7d} {len(runs) - len(speeds):8d} {off:>17}",
                  flush=True)
    return 0


if __name__ == "__main__":
    install()  # lockstep flights fly the bundled SITL in this process
    sys.exit(main())
