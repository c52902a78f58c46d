"""`quadgcs campaign FILE.toml`: many seeded lockstep flights from one file, on Ray.

Each run is `quadgcs fly --lockstep` with the file's flight and one combination of its axes
(station gains, estimator settings, worlds and their sensor noise, profiles, seeds), or
`quadgcs mission run --lockstep` with the file's mission, a seed and its planner keys, as a Ray
task: an embedded local Ray on this machine's CPUs by default, a cluster with `--address` (or
RAY_ADDRESS). Results: one row per run in OUTPUT/results.parquet (and .csv with --csv), a summary
on stdout, PNG plots in OUTPUT/plots. Re-running the same file resumes: runs already in the
results are skipped. Ctrl-C stops and keeps every finished run. `kind = "search"` tunes the
axes with Optuna (TPE) and writes OUTPUT/best_station.toml for `quadgcs fly --config`.
See lab/campaign/spec.py and campaigns/ for the file format.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

from gcs.errors import UsageError

DEFAULT_OUTPUT = Path("flights") / "campaigns"


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add the `campaign` subcommand."""
    p = sub.add_parser("campaign", help="fly a campaign file's seeded lockstep runs on Ray",
                       description=__doc__,
                       formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("file", type=Path, help="campaign TOML (see campaigns/)")
    p.add_argument("--address", metavar="HOST:PORT",
                   help="join this Ray cluster (default: RAY_ADDRESS, else a local Ray)")
    p.add_argument("--workers", type=int, metavar="N",
                   help="CPUs of the local Ray (default: all of this machine's)")
    p.add_argument("-o", "--output", type=Path,
                   help=f"results directory (default {DEFAULT_OUTPUT}/NAME)")
    p.add_argument("--csv", action="store_true", help="also write results.csv")
    p.add_argument("--no-plots", action="store_true", help="draw no PNG plots")
    p.add_argument("-q", "--quiet", action="store_true", help="no progress line")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """CLI entry: load, fly on Ray, print the summary; 130 when interrupted."""
    from lab.campaign import (
        BaseMission,
        load_campaign,
        mission_summary_table,
        ray_session,
        run_campaign,
        run_search,
        summary_table,
    )
    from lab.campaign.plots import axis_plots
    from lab.campaign.pool import need
    from lab.faultsearch.spec import is_fault_search

    if is_fault_search(args.file):
        return _fault_search(args)
    c = load_campaign(args.file)
    need("pyarrow")  # the results file: before any run, not after the first
    if args.workers is not None and args.workers < 1:
        raise UsageError(f"--workers {args.workers}: expected at least 1")
    out_dir = args.output or DEFAULT_OUTPUT / c.name
    cpus = args.workers or os.cpu_count() or 1
    with ray_session(args.address, cpus) as ray:
        if c.kind == "search":
            found = run_search(c, out_dir, ray, csv=args.csv, quiet=args.quiet)
            outcome = found.outcome
        else:
            found = None
            outcome = run_campaign(c, out_dir, ray, csv=args.csv, quiet=args.quiet)
    axes = list(c.axes) + (["world"] if c.kind == "search" and len(c.search.worlds) > 1
                           else [])
    missions = isinstance(c.base, BaseMission)
    print(mission_summary_table(outcome.rows, axes) if missions
          else summary_table(outcome.rows, axes))
    failed = sum(r.get("status") != "ok" for r in outcome.rows)
    print(f"{len(outcome.rows)} runs in {outcome.results} ({outcome.ran} flown now, "
          f"{outcome.skipped} already there, {failed} failed)")
    if found is not None:
        print(f"best of {found.trials} trials: {c.search.objective} {found.best_value:.5f} "
              f"with {found.best_params}; station file {found.best_config}")
    if not args.no_plots:
        metric = (c.search.objective if c.kind == "search"
                  else "min_clearance_m" if missions else "rms_error_m")
        pics = axis_plots(outcome.rows, axes or ["seed"], metric, out_dir / "plots")
        if pics is None:
            print("plots: none drawn (matplotlib is not installed: pip install 'quadgcs[plot]')")
        else:
            shown = [*pics, *([found.history] if found is not None and found.history else [])]
            print(f"plots: {', '.join(str(p) for p in shown)}")
    if not outcome.complete:
        print(f"quadgcs campaign: interrupted; {len(outcome.rows)} finished runs kept in "
              f"{outcome.results} (run the same file again to resume)", file=sys.stderr)
        return 130
    return 0


def _fault_search(args: argparse.Namespace) -> int:
    """kind = "fault-search": hunt for unsafe flights (lab.faultsearch)."""
    from lab.campaign import ray_session
    from lab.campaign.pool import need
    from lab.faultsearch.campaign import PLOT, RESULTS, margins_plot, run_fault_campaign
    from lab.faultsearch.campaign import summary_table as fault_table
    from lab.faultsearch.spec import load_fault_campaign

    c = load_fault_campaign(args.file)
    need("pyarrow")
    need("optuna")
    if args.workers is not None and args.workers < 1:
        raise UsageError(f"--workers {args.workers}: expected at least 1")
    out_dir = args.output or DEFAULT_OUTPUT / c.name
    cpus = args.workers or os.cpu_count() or 1
    with ray_session(args.address, cpus) as ray:
        workers = int(ray.cluster_resources().get("CPU", cpus))
        rows, found = run_fault_campaign(c, out_dir, ray, workers, quiet=args.quiet)
    print(fault_table(rows, found))
    print(f"{len(rows)} runs in {out_dir / RESULTS}; {len(found)} properties violated")
    for v in found:
        print(f"{v.prop}: run {v.run}, margin {v.margin:.3f} ({v.note}); shrunk schedule "
              f"{v.schedule}\n  {v.command}")
    if not args.no_plots:
        pic = margins_plot(rows, out_dir / PLOT)
        print(f"plot: {pic}" if pic else "plot: none drawn (matplotlib is not installed)")
    return 130 if len(rows) < c.runs else 0
