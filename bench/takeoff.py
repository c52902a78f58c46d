"""Take-off overshoot over many seeds: how far past its target a take-off carries the vehicle.

Flies `quadgcs fly --hold 4` in lockstep on the bundled SITL, recorded, per seed, profile and
target (1 and 2 m), and scores the SITL's truth from the moment the supervisor hands the climb to
the hold until it asks for the landing: the peak height (above the floor where the vehicle
stood, plus the estimate's rest height, as the station measures) over the target, in per cent of
the target. The issue's floor is 5 %; `tests/e2e/test_takeoff.py` flies seed 5 to it.

The climb's own first peak is printed beside it (the hold's later wander, on 3.2.1's 6 cm
sonar steps, can top it). It also prints where the station recognised the lift-off: the truth
height when the hold took over (a hand-over with the vehicle still on the floor, under 0.5 cm,
is a lift-off felt that was not one).

    nice -n 10 .venv/bin/python bench/takeoff.py [--seeds 1-60] [--profiles apm25,copter4]
"""

from __future__ import annotations

import argparse
import re
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from bench.open_loop import seed_range
from gcs import topics
from gcs.commands.fly import fly_session
from gcs.config import StationConfig
from gcs.flight import FlightPlan
from gcs.lockstep_session import LockstepSession
from gcs.scoring import takeoff_peak_m, truth_origin_m
from gcs.station.session import SessionOptions
from lab.lockstep import install
from logs import open_recording

TARGETS_M = (1.0, 2.0)
HOLD_S = 4.0


@dataclass(frozen=True, slots=True)
class Takeoff:
    """One take-off: its overshoot and where the station recognised the lift-off."""

    overshoot_pct: float  # the highest from the hand-over until the landing (the hold's too)
    first_peak_pct: float  # the climb's own: its first peak once within 10 % of the target
    handover_m: float  # truth height above the floor when the hold took over
    handover_us: int  # the ramp's throttle then (from the transition's reason), 0 if unknown


def takeoff(profile: str, seed: int, alt_m: float, tmp: Path) -> Takeoff:
    """Fly one take-off to `alt_m` and score it from the SITL's truth."""
    out = tmp / f"{profile}-{seed}-{alt_m:g}.mcap"
    options = SessionOptions(command="fly", profile=profile, seed=seed, record=True,
                             output=out, fix_failsafe=True)
    with LockstepSession(options) as session:
        fly_session(session, FlightPlan(alt_m=alt_m, hold_s=HOLD_S), pilot_signals=False)
    moves: dict[tuple[str, str], float] = {}
    reasons: dict[tuple[str, str], str] = {}
    truth: list[tuple[float, float]] = []
    for topic, ns, msg in open_recording(out).messages([topics.SUPERVISOR, topics.SIM_TRUTH]):
        if topic == topics.SUPERVISOR:
            moves[(msg["previous"], msg["state"])] = ns / 1e9
            reasons[(msg["previous"], msg["state"])] = msg.get("reason", "")
        else:
            truth.append((ns / 1e9, -msg["pos_n"]["z"]))
    t, h = (np.array(x) for x in zip(*truth, strict=True))
    rest = StationConfig().estimator.rest_alt_m
    armed_s, flying_s = moves[("arming", "manual")], moves[("takeoff", "hold")]
    peak = takeoff_peak_m(t, h, armed_s, flying_s, moves[("hold", "vehicle")], rest)
    origin = truth_origin_m(h[t < armed_s], rest)
    assert origin is not None
    at = float(np.interp(flying_s, t, h)) - origin  # on the station scale: rest included
    m = re.search(r"at (\d+) us", reasons[("takeoff", "hold")])
    first = first_peak_m(h[t > flying_s] - origin, alt_m)
    return Takeoff((peak - alt_m) / alt_m * 100.0, (first - alt_m) / alt_m * 100.0, at - rest,
                   int(m.group(1)) if m else 0)


def first_peak_m(h: np.ndarray, alt_m: float, drop_m: float = 0.03) -> float:
    """The climb's first peak: the highest it went, from the hand-over, until it first came
    `drop_m` down from its highest after getting within 10 % of `alt_m` (the hold's later
    wander, on 3.2.1's 6 cm sonar steps, is the hold's, not the take-off's)."""
    near = np.flatnonzero(h >= 0.9 * alt_m)
    if not len(near):
        return float(h.max())
    top = np.maximum.accumulate(h[near[0]:])
    fell = np.flatnonzero(h[near[0]:] < top - drop_m)
    end = near[0] + (fell[0] if len(fell) else len(top))
    return float(h[:end].max())


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", default="1-60", help="SITL seeds, FIRST-LAST (default 1-60)")
    ap.add_argument("--profiles", default="apm25,copter4", help="comma-separated profiles")
    ap.add_argument("--targets", default="1,2", help="comma-separated take-off altitudes (m)")
    ap.add_argument("-v", "--verbose", action="store_true", help="one line per take-off too")
    args = ap.parse_args()
    seeds = seed_range(args.seeds)
    print(f"lockstep take-off, then a {HOLD_S:g} s hold, seeds {seeds[0]}-{seeds[-1]}, truth; "
          "hand-over: height above the floor when the hold took the climb over")
    print(f"{'profile':8} {'target m':>8} {'overshoot % med/max':>20} {'over 5 %':>8} "
          f"{'first peak % med/max':>21} {'over 5 %':>8} "
          f"{'hand-over cm min/med/max':>25} {'on the floor':>12}")
    worst = 0.0
    with tempfile.TemporaryDirectory() as tmp:
        for profile in args.profiles.split(","):
            for alt_m in (float(x) for x in args.targets.split(",")):
                runs = []
                for seed in seeds:
                    runs.append(takeoff(profile, seed, alt_m, Path(tmp)))
                    if args.verbose:
                        r = runs[-1]
                        print(f"  seed {seed:3d}: overshoot {r.overshoot_pct:6.2f} %, first peak "
                              f"{r.first_peak_pct:6.2f} %, hand-over "
                              f"at {r.handover_m * 100:5.1f} cm, {r.handover_us} us", flush=True)
                pct = np.array([r.overshoot_pct for r in runs])
                first = np.array([r.first_peak_pct for r in runs])
                hand = np.array([r.handover_m for r in runs]) * 100.0
                worst = max(worst, float(pct.max()))
                print(f"{profile:8} {alt_m:8.1f} {np.median(pct):9.2f} / {pct.max():<8.2f} "
                      f"{int(np.sum(pct > 5.0)):8d} {np.median(first):10.2f} / {first.max():<8.2f} "
                      f"{int(np.sum(first > 5.0)):8d} {hand.min():9.1f} / {np.median(hand):4.1f} / "
                      f"{hand.max():<5.1f} {int(np.sum(hand < 0.5)):12d}", flush=True)
    print(f"worst overshoot {worst:.2f} % (floor: 5 %)")
    return 0


if __name__ == "__main__":
    install()  # lockstep flights fly the bundled SITL in this process
    sys.exit(main())
