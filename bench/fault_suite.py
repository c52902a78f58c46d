"""The station falls silent, in every failsafe configuration the pre-flight accepts.

Flies `quadgcs fly` (1.0 m, 30 s hold) in lockstep on the bundled SITL and, from t = 25 s
(simulated, about 15 s into the hold), kills the link: the uplink for 15 s, both ways for
15 s, or both ways for good (the station and its guardian gone: nothing lands the vehicle but its
own failsafe). Each vehicle configuration is one the pre-flight accepts, flown with the RC
receiver absent and at minimum:

- copter4 `fix`: the pre-flight's own fix (FS_OPTIONS 0, FS_GCS_ENABLE 5 Land, FS_GCS_TIMEOUT 2)
- copter4 `rtl-no-gps`: FS_GCS_ENABLE 1 (RTL) without a GPS fix, which lands (FS_OPTIONS 0)
- apm25 `no-gps`: 3.2.1's GCS failsafe without a GPS fix: LAND
- apm25 `gps-rtl-alt-0`: with a fix RTL, RTL_ALT 0: returns at its height, then lands

Heights are the SITL's truth, judged from the level the hold kept before the fault. Per row:
the peak over the hold (median, worst, flights above + 0.3 m), the touchdown speed (median,
worst, flights over 1.0 m/s), flights that never came down, and the autopilot's disarm counted
from the fault (median, worst, flights later than 20 s; watched 35 s). Exit 1 when any
flight broke a bound.

    .venv/bin/python bench/fault_suite.py [--seeds 1-60] [--profiles apm25,copter4]
        [--faults up,both,silent] [--rc absent,min] [--hold-mode climb-rate|throttle]
        [--config STATION.toml] [--jobs 2]
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import statistics
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import NamedTuple

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from gcs.commands.fly import fly_session
from gcs.config import HoldMode, load_config
from gcs.errors import FlightFailed
from gcs.flight import FlightPlan
from gcs.lockstep_session import LockstepSession
from gcs.station.session import SessionOptions
from lab.lockstep import install
from sitl.autopilot import AutopilotOptions
from sitl.autopilot.profile import RcInput
from sitl.world import default_world

FAULT_AT_S = 25.0
HOLD_S = 30.0  # the fault comes ~15 s into it, long after the hold has settled
FADE_S = 15.0
SILENT_S = 1.0e6  # "for good"
SETPOINT_M = 1.0
WATCH_S = 35.0  # watched from the fault: past the 20 s bound, with room for a slow LAND
FLOOR_BAND_M = 0.03
HELD_S = 10.0
RISE_BOUND_M = 0.3
TOUCHDOWN_BOUND_MPS = 1.0
DISARM_BOUND_S = 20.0

# (profile, name) -> (receiver-independent autopilot settings, gps)
CONFIGS: dict[tuple[str, str], tuple[tuple[tuple[str, float], ...], bool]] = {
    ("copter4", "fix"): ((), False),
    ("copter4", "rtl-no-gps"): ((("FS_GCS_ENABLE", 1.0), ("FS_OPTIONS", 0.0),
                                 ("FS_GCS_TIMEOUT", 2.0)), False),
    ("apm25", "no-gps"): ((), False),
    ("apm25", "gps-rtl-alt-0"): ((("RTL_ALT", 0.0), ("FS_GCS_ENABLE", 1.0)), True),
}
FAULTS = {"up": ("up", FADE_S), "both": ("both", FADE_S), "silent": ("both", SILENT_S)}


class Case(NamedTuple):
    profile: str
    config: str
    rc: str
    fault: str
    seed: int
    station_config: str | None
    hold_mode: str | None


class Outcome(NamedTuple):
    peak_m: float  # on the setpoint's scale
    touchdown_mps: float | None
    disarm_s: float | None  # from the fault's start
    refused: str | None  # the pre-flight's line when it refused the vehicle


def fly_case(case: Case) -> Outcome:
    """One flight of `case`; the SITL runs on after the station has given up."""
    params, gps = CONFIGS[(case.profile, case.config)]
    room = default_world()
    # a tall room: a vehicle carried up blind meets no ceiling (which stalls the SITL's LAND)
    world = dataclasses.replace(
        room, autopilot=AutopilotOptions(rc_input=RcInput(case.rc), gps=gps, params=params),
        room_min_n=(*room.room_min_n[:2], -30.0))
    options = SessionOptions(
        command="fly", profile=case.profile, seed=case.seed, record=False, fix_failsafe=True,
        config=Path(case.station_config) if case.station_config else None)
    direction, length = FAULTS[case.fault]
    faults = {"fade": direction, "fade_start_s": FAULT_AT_S, "fade_s": length}
    config = load_config(options.config)
    if case.hold_mode is not None:
        config = dataclasses.replace(config, hold_mode=HoldMode(case.hold_mode))
    with LockstepSession(options, world=world, faults=faults, config=config) as session:
        pre = session.preflight[1]
        if not pre.ok:
            return Outcome(0.0, None, None, pre.summary())
        vehicle = session.first
        with contextlib.suppress(FlightFailed):  # the fault is the point
            fly_session(session, FlightPlan(alt_m=SETPOINT_M, hold_s=HOLD_S), pilot_signals=False)
        state = session.sitl.sitl.sim.vehicle(1).autopilot.state
        disarmed = None if state.armed else session.clock.now_s() - FAULT_AT_S
        end = FAULT_AT_S + WATCH_S
        while session.clock.now_s() < end and vehicle.truth is not None:
            session.sitl.sitl.advance_to(session.clock.now_s() + 0.1)
            vehicle.truth.reports()
            if disarmed is None and not state.armed:
                disarmed = session.clock.now_s() - FAULT_AT_S
        series = vehicle.truth_series()
    assert series is not None, "lockstep flies with the truth endpoint"
    t, alt = series.t_s, series.alt_m
    floor = float(alt[: max(1, min(50, alt.size))].min())
    after = t >= FAULT_AT_S
    held = float(np.median(alt[(t >= FAULT_AT_S - HELD_S) & ~after]))
    peak = SETPOINT_M + float(alt[after].max()) - held
    down = np.nonzero(after & (alt <= floor + FLOOR_BAND_M))[0]
    if not down.size:
        return Outcome(peak, None, disarmed, None)
    t_c = t[down[0]]
    sel = (t >= t_c - 0.25) & (t <= t_c)
    speed = float(max(0.0, -np.polyfit(t[sel] - t_c, alt[sel], 1)[0]))
    return Outcome(peak, speed, disarmed, None)


def _run(case: Case) -> tuple[Case, Outcome]:
    install()
    return case, fly_case(case)


def seed_range(text: str) -> list[int]:
    """FIRST-LAST (or one seed) as the list of seeds."""
    first, _, last = text.partition("-")
    return list(range(int(first), int(last or first) + 1))


def _row(runs: list[Outcome]) -> tuple[str, int]:
    """The printed row and how many flights broke a bound."""
    refused = [r for r in runs if r.refused]
    if refused:
        return f"refused by the pre-flight: {refused[0].refused}", 0
    peaks = [r.peak_m for r in runs]
    speeds = [r.touchdown_mps for r in runs if r.touchdown_mps is not None]
    offs = [r.disarm_s for r in runs if r.disarm_s is not None]
    high = sum(p > SETPOINT_M + RISE_BOUND_M for p in peaks)
    fast = sum(v > TOUCHDOWN_BOUND_MPS for v in speeds)
    late = sum(d > DISARM_BOUND_S for d in offs) + len(runs) - len(offs)
    up = len(runs) - len(speeds)
    touch = f"{statistics.median(speeds):.2f} / {max(speeds):.2f}" if speeds else "-"
    off = f"{statistics.median(offs):.1f} / {max(offs):.1f}" if offs else "-"
    text = (f"{statistics.median(peaks):5.2f} / {max(peaks):5.2f} {high:4d}  {touch:>11} "
            f"{fast:4d}  {up:4d}  {off:>11} {late:4d}")
    return text, sum(not _within(r) for r in runs)


def _within(r: Outcome) -> bool:
    """Whether one flight kept every bound."""
    return (r.peak_m <= SETPOINT_M + RISE_BOUND_M and r.touchdown_mps is not None
            and r.touchdown_mps <= TOUCHDOWN_BOUND_MPS and r.disarm_s is not None
            and r.disarm_s <= DISARM_BOUND_S)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", default="1-60", help="SITL seeds, FIRST-LAST (default 1-60)")
    ap.add_argument("--profiles", default="apm25,copter4")
    ap.add_argument("--faults", default="up,both,silent")
    ap.add_argument("--rc", default="absent,min", help="receiver: absent, min, mid")
    ap.add_argument("--config", default=None, help="station TOML")
    ap.add_argument("--hold-mode", choices=[m.value for m in HoldMode], default=None,
                    help="the PC hold (default: the station TOML's, else throttle)")
    ap.add_argument("--jobs", type=int, default=2, help="processes (default 2)")
    args = ap.parse_args()
    seeds = seed_range(args.seeds)
    profiles, faults, rcs = (args.profiles.split(","), args.faults.split(","),
                             args.rc.split(","))
    for name in faults:
        if name not in FAULTS:
            ap.error(f"--faults: {name!r} is not one of {', '.join(FAULTS)}")
    groups = [(p, c, rc, f) for (p, c) in CONFIGS if p in profiles for rc in rcs for f in faults]
    cases = [Case(p, c, rc, f, s, args.config, args.hold_mode)
             for (p, c, rc, f) in groups for s in seeds]
    print(f"lockstep, {SETPOINT_M:g} m hold, fault from t = {FAULT_AT_S:g} s (up/both "
          f"{FADE_S:g} s, silent: for good), seeds {seeds[0]}-{seeds[-1]}, truth heights, "
          f"station config {args.config or 'default'}, hold mode {args.hold_mode or 'default'}")
    print(f"{'profile':8} {'config':14} {'rc':6} {'fault':6} {'peak m med/max':>15} "
          f"{'>+0.3':>5} {'touch m/s':>11} {'>1':>4} {'up':>5} {'disarm s':>11} {'>20':>4}")
    results: dict[tuple[str, str, str, str], list[Outcome]] = {g: [] for g in groups}
    with ProcessPoolExecutor(max_workers=args.jobs) as pool:
        for case, outcome in pool.map(_run, cases):
            results[(case.profile, case.config, case.rc, case.fault)].append(outcome)
    broken = 0
    for g in groups:
        text, bad = _row(results[g])
        broken += bad
        print(f"{g[0]:8} {g[1]:14} {g[2]:6} {g[3]:6} {text}", flush=True)
    print(f"flights breaking a bound: {broken} of {len(cases)}")
    return 1 if broken else 0


if __name__ == "__main__":
    sys.exit(main())
