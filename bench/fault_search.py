"""Fault search: runs-to-find for the faults this project fixed, and a search of the product.

1. Known bugs (tests/lab/faultsearch/known_bugs.py): each put back by monkeypatching, then the
   search (random first, then TPE) and plain random sampling, each with the same budget, over
   the bug's focused space and over the default space (every kind, the whole flight): how many
   runs until the property that should catch it is violated ("-" : not within the budget).
2. The product as it is, per profile: a search of `--runs` runs on Ray (`--workers`), printing
   runs per minute, violations by property, and each one's shrunk schedule and reproduction
   command (files under --out).

Prints numbers; asserts nothing. The product search is CPU-heavy: on a shared machine run it as
`nice -n 15`.

    python bench/fault_search.py [--known] [--budget 300] [--default-space]
                                 [--product apm25,copter4] [--runs 2000] [--workers 2]
                                 [--out flights/fault_search]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from gcs.flight_plan import FlightPlan  # noqa: E402
from lab.faultsearch.campaign import (  # noqa: E402
    margins_plot,
    pool_executor,
    run_fault_campaign,
    summary_table,
)
from lab.faultsearch.runner import SearchFlight  # noqa: E402
from lab.faultsearch.search import SearchOptions, search  # noqa: E402
from lab.faultsearch.space import Space  # noqa: E402
from lab.faultsearch.spec import FaultCampaign  # noqa: E402
from tests.lab.faultsearch.known_bugs import BUGS, KnownBug, inserted  # noqa: E402

PLAN = FlightPlan(alt_m=0.6, hold_s=1.0, step_m=0.2, step_observe_s=1.5)


def _flight(profile: str) -> SearchFlight:
    return SearchFlight(profile=profile, plan=PLAN, fix_failsafe=profile == "copter4")


def runs_to_find(bug: KnownBug, space: Space, sampler: str, budget: int, seed: int) -> str:
    """How many runs the sampler needed to violate the bug's property ("-": none)."""
    with inserted(bug):
        found = search(_flight(bug.profile), space,
                       SearchOptions(runs=budget, random_runs=min(budget, 10), sampler=sampler,
                                     sample_seed=seed, until=bug.prop))
    return "-" if found.found_at is None else str(found.found_at)


def known(budget: int, default_space: bool, seed: int) -> None:
    print(f"known bugs: runs to find (budget {budget}, sampler seed {seed})")
    print(f"{'bug':64s} {'property':10s} {'space':8s} {'search':>7s} {'random':>7s}")
    for bug in BUGS:
        spaces = [("focused", bug.space)]
        if default_space:
            spaces.append(("default", Space()))
        for label, space in spaces:
            w0 = time.perf_counter()
            s = runs_to_find(bug, space, "tpe", budget, seed)
            r = runs_to_find(bug, space, "random", budget, seed)
            print(f"{bug.name:64s} {bug.prop:10s} {label:8s} {s:>7s} {r:>7s}   "
                  f"({time.perf_counter() - w0:.0f} s)", flush=True)


def product(profile: str, runs: int, workers: int, out: Path, use_ray: bool,
            shrink: int) -> None:
    c = FaultCampaign(out / f"{profile}.toml", f"fault_search_{profile}", runs, None, 0, shrink,
                      _flight(profile), Space(), None)
    w0 = time.perf_counter()
    if use_ray:
        from lab.campaign.pool import ray_session

        with ray_session(None, workers) as ray:
            rows, found = run_fault_campaign(c, out / profile, ray, workers)
    else:  # worker processes of our own, reused run after run
        import multiprocessing

        with multiprocessing.get_context("forkserver").Pool(workers) as pool:
            rows, found = run_fault_campaign(c, out / profile, None, workers,
                                             execute=pool_executor(pool))
    minutes = (time.perf_counter() - w0) / 60.0
    print(f"\n{profile}: {len(rows)} runs in {minutes:.1f} min = {len(rows) / minutes:.1f} "
          f"runs/min on {workers} workers (shrinking included)")
    print(summary_table(rows, found))
    for v in found:
        print(f"  {v.prop}: {v.count} runs, worst margin {v.margin:.3f} at run {v.run} "
              f"({v.note})\n    {v.command}")
    pic = margins_plot(rows, out / profile / "margins.png")
    if pic is not None:
        print(f"  plot: {pic}")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--known", action="store_true", help="runs-to-find of the known bugs")
    ap.add_argument("--budget", type=int, default=300)
    ap.add_argument("--default-space", action="store_true",
                    help="known bugs over the default space too (slow)")
    ap.add_argument("--seed", type=int, default=1, help="the samplers' seed")
    ap.add_argument("--product", default="", help="profiles to search, e.g. apm25,copter4")
    ap.add_argument("--runs", type=int, default=2000)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--shrink", type=int, default=6, help="flights spent shrinking each violation")
    ap.add_argument("--out", type=Path, default=ROOT / "flights" / "fault_search")
    ap.add_argument("--ray", action="store_true",
                    help="fly on Ray (as a campaign does) instead of a process pool")
    args = ap.parse_args()
    if args.known:
        known(args.budget, args.default_space, args.seed)
    for profile in [p for p in args.product.split(",") if p]:
        product(profile, args.runs, args.workers, args.out, args.ray, args.shrink)
    return 0


if __name__ == "__main__":
    sys.exit(main())
