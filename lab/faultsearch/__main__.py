"""Fly one schedule as a fault search does and print every property's margin:

    python -m lab.faultsearch --seed N --faults FILE [--profile apm25] [--alt 0.6] [--hold 1]
                              [--step 0.2] [--step-watch 1.5] [--world FILE] [--fix-failsafe]

`quadgcs fly --lockstep` with the same flags replays the same flight; this says what the search
judged of it. Exit status 1 when a property is violated, 2 for a bad flag or file.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from gcs.errors import UsageError
from gcs.flight_plan import FlightPlan
from lab.faultsearch.runner import SearchFlight, fly_schedule
from lab.faultsearch.schedule import flight_span_s, load_schedule


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m lab.faultsearch", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seed", type=int, required=True, help="the run's seed")
    ap.add_argument("--faults", type=Path, required=True, help="the schedule file (TOML)")
    ap.add_argument("--profile", default="apm25", choices=("apm25", "copter4"))
    ap.add_argument("--alt", type=float, default=0.6, help="hold altitude, m")
    ap.add_argument("--hold", type=float, default=1.0, help="hold time, s")
    ap.add_argument("--step", type=float, default=0.2, help="step after the hold, m")
    ap.add_argument("--step-watch", type=float, default=1.5, help="watch the step this long, s")
    ap.add_argument("--world", type=Path, help="world file")
    ap.add_argument("--fix-failsafe", action="store_true", help="as fly's --fix-failsafe")
    args = ap.parse_args(argv)
    try:
        plan = FlightPlan(alt_m=args.alt, hold_s=args.hold, step_m=args.step,
                          step_observe_s=args.step_watch)
        schedule = load_schedule(args.faults, flight_span_s(plan))
    except (ValueError, UsageError) as exc:
        print(f"python -m lab.faultsearch: {exc}", file=sys.stderr)
        return 2
    flight = SearchFlight(args.profile, args.world, plan, args.fix_failsafe)
    run = fly_schedule(flight, args.seed, schedule)
    for m in sorted(run.margins, key=lambda m: m.margin):
        print(f"{m.name:12s} {m.margin:+9.3f}  at {m.t_s:6.2f} s  {m.note}")
    print(f"fly: {'exit 0' if run.exit_ok else 'failed: ' + run.exit_reason}")
    return 1 if run.violated else 0


if __name__ == "__main__":
    sys.exit(main())
