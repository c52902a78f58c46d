"""Position legs in lockstep: overshoot and settling of the horizontal hold, per profile.

Takes off to 1 m on the bundled SITL (lockstep: the station's own code on simulated time,
motion capture for position), then moves the set point by each leg north and south across
the start, and prints per leg: overshoot past the new spot (% of the leg), time to stay within
±5 cm, the largest excursion off the line (east) and of the altitude. Floors from the mission
issue: a 0.5 m leg within ±5 cm in ≤ 2 s with ≤ 10 % overshoot; a 2 m leg in ≤ 4 s.

    .venv/bin/python bench/position_legs.py [--seeds 1-50] [--legs 0.5,2.0]
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from bench.open_loop import seed_range
from gcs.position_legs import fly_legs


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", default="1-50", help="SITL seeds, FIRST-LAST (default 1-50)")
    ap.add_argument("--legs", default="0.5,2.0", help="leg lengths in metres, comma-separated")
    args = ap.parse_args()
    seeds = seed_range(args.seeds)
    legs = tuple(float(x) for x in args.legs.split(","))
    print(f"lockstep, seeds {seeds[0]}-{seeds[-1]}, legs {legs} m north and south across the "
          "start, band ±5 cm, 10 s each")
    print(f"{'profile':8} {'leg m':>5} {'overshoot % med/max':>20} {'settle s med/max':>17} "
          f"{'cross cm':>8} {'alt dev cm':>10}")
    for profile in ("apm25", "copter4"):
        runs = [fly_legs(profile, legs + legs, seed=s, observe_s=10.0) for s in seeds]
        for leg in legs:
            rs = [r for run in runs for r in run if r.leg_m == leg]
            ov = [r.overshoot_pct for r in rs]
            st = [r.settle_s for r in rs]

            def fmt(x: float) -> str:
                return "never" if math.isinf(x) else f"{x:.1f}"

            print(f"{profile:8} {leg:5.1f} {statistics.median(ov):9.0f} / {max(ov):4.0f}"
                  f"      {fmt(statistics.median(st)):>5} / {fmt(max(st)):>5}"
                  f"   {100 * max(r.max_cross_m for r in rs):6.1f}"
                  f"   {100 * max(r.alt_dev_m for r in rs):8.1f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
