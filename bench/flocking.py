"""Triangular leader–follower flock vs the Reynolds baseline, kinematic mode, 5/15/31 vehicles.

Prints one row per (scene, team size, planner): time to goal of the root leader and of the
followers (mean / last), formation error, minimum separation, collisions, messages, throughput
through the door, and how the run ended. Messages are counted in the all-to-all baseline's unit,
one per ordered pair of vehicles and step: for the flock ``pos`` is eq. 9.1's leader positions,
``reads`` every other use of a teammate's state (the guard's positions and planned set points,
make-way requests, a leader's queueing flag, settled flags), ``total`` their sum; Reynolds is
billed N·(N−1) per step. A closing summary gives Reynolds's total over the flock's per scene
and size. Rows: ``triangular`` (followers use the leader's
heads-up trail), ``tri-self`` (followers avoid on their own sensors only), ``tri-flat`` (door
scene: heads-up on one level, ``n_layers=1``, to show what the altitude layers change) and
``reynolds``. Run from the repository
root (``bench/planners.py`` would shadow the package if run as a script):
``.venv/bin/python -m bench.flocking [sizes...]``.
"""

from __future__ import annotations

import statistics
import sys
import time

import numpy as np

from gcs.mission.kinematic_flock import FlockResult, fly_flock_scene
from planners.flocking.planner import FlockParams, FollowerPolicy
from planners.flocking.scenes import all_scenes
from planners.flocking.swarm import PlannerFactory, reynolds_factory, triangular_factory

MAX_STEPS = 1200
SEED = 7


def _fmt(x: float | None, spec: str = ".1f") -> str:
    return "-" if x is None else format(x, spec)


def _row(label: str, r: FlockResult, wall_s: float) -> str:
    fol = [t for t in r.follower_times_s if t is not None]
    fol_mean = statistics.fmean(fol) if fol else None
    fol_last = max(fol) if len(fol) == len(r.follower_times_s) and fol else None
    return (
        f"{r.scene:6} {r.n_vehicles:3d} {label:10} {_fmt(r.leader_time_s):>7} "
        f"{_fmt(fol_mean):>7} {_fmt(fol_last):>7} {_fmt(r.formation_error_m, '.2f'):>6} "
        f"{r.min_separation_m:6.2f} {r.obstacle_collisions:4d} {r.vehicle_collisions:4d} "
        f"{r.messages_sent:8d} {r.state_reads:8d} {r.messages_total:8d} "
        f"{_fmt(r.throughput_vps, '.2f'):>6}  "
        f"{r.status.value}: {r.reason} [{wall_s:.1f} s]"
    )


def main(argv: list[str]) -> None:
    """Run every scene, size and planner; print the table."""
    sizes = [int(a) for a in argv] or [5, 15, 31]
    print(
        "scene    N planner     lead_s  fol_s  fol_last  ferr_m  minsep  obsC  vehC"
        "       pos    reads    total  veh/s  status"
    )
    ratios: list[str] = []
    for n in sizes:
        for scene in all_scenes():
            planners: list[tuple[str, PlannerFactory]] = [
                ("triangular", triangular_factory()),
                ("tri-self", triangular_factory(FlockParams(policy=FollowerPolicy.SELF_AVOID))),
            ]
            if scene.gate is not None:
                planners.append(("tri-flat", triangular_factory(FlockParams(n_layers=1))))
            planners.append(("reynolds", reynolds_factory()))
            totals: dict[str, FlockResult] = {}
            for label, factory in planners:
                t0 = time.perf_counter()
                r = fly_flock_scene(scene, n, factory, MAX_STEPS, np.random.default_rng(SEED))
                print(_row(label, r, time.perf_counter() - t0), flush=True)
                totals[label] = r
            tri, rey = totals["triangular"], totals["reynolds"]
            ratios.append(
                f"  {scene.name:6} N={n:<3} reynolds/triangular messages "
                f"{rey.messages_total / max(1, tri.messages_total):5.2f}x per run, "
                f"{_per_step(rey) / max(1e-9, _per_step(tri)):5.2f}x per step "
                f"(triangular: {tri.state_reads / max(1, tri.messages_total):.0%} of it reads; "
                f"{tri.steps} vs {rey.steps} steps)"
            )
    print("Messages, all counted (eq. 9.1 positions + state reads vs N(N-1) per step):")
    print("\n".join(ratios))


def _per_step(r: FlockResult) -> float:
    return r.messages_total / max(1, r.steps)


if __name__ == "__main__":
    main(sys.argv[1:])
