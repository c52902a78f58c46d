"""Lockstep flights and campaigns: how fast, how they scale, what Ray costs. Prints numbers only.

1. Lockstep speed: one `fly --lockstep` 30 s hold at 1 m (one vehicle, the SITL's full sensor
   set, 40 Hz streams, motion capture and truth), simulated seconds per CPU second of this
   process, without and with the MCAP recording. Goal: >= 100x. With the compiled SITL
   (`sitl.native`), the same again in a child process with it switched off.
2. Campaign throughput: `--flights` (default 200) seeded 30 s hold flights as one grid
   campaign on an embedded local Ray with `--workers` (default 2) workers: flights per minute
   of wall time from the first task to the last row (Ray's start and stop apart, printed too).
   Goal: >= 100 flights per minute on 2 cores.
3. Scaling: `--scaling-flights` (default 40) flights with 1 worker, then with 2. Goal: >= 1.8x.
4. Ray's overhead per run: a no-op task's round trip, and the wall time per run of the 1-worker
   campaign beyond the CPU the runs themselves used.

    .venv/bin/python bench/campaign.py [--flights 200] [--scaling-flights 40] [--workers 2]
                                       [--speed-only]
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from gcs.commands.fly import fly_session
from gcs.flight import FlightPlan
from gcs.lockstep_session import LockstepSession
from gcs.station.session import SessionOptions
from lab.campaign import load_campaign, ray_session, run_campaign
from lab.lockstep import install
from sitl import native

HOLD_S = 30.0


def lockstep_speed(record: bool, seed: int = 3) -> tuple[float, float, float]:
    """(simulated s, CPU s, hold RMS m) of one lockstep flight; the best of two."""
    best: tuple[float, float, float] | None = None
    with tempfile.TemporaryDirectory() as tmp:
        for k in range(2):
            c0 = time.process_time()
            opts = SessionOptions(command="fly", seed=seed, record=record,
                                  output=Path(tmp) / f"f{k}.mcap")
            session = LockstepSession(opts)
            with session:
                d = fly_session(session, FlightPlan(hold_s=HOLD_S), pilot_signals=False)
                sim_s = session.clock.now_s()
            cpu_s = time.process_time() - c0
            if best is None or cpu_s < best[1]:
                best = (sim_s, cpu_s, float(d["rms_error_m"]))
    assert best is not None
    return best


def _campaign_file(tmp: Path, flights: int, first_seed: int) -> Path:
    path = tmp / f"bench_{flights}_{first_seed}.toml"
    path.write_text(f"""name = "bench"
[fly]
alt_m = 1.0
hold_s = {HOLD_S}
[axes]
seed = {{ range = [{first_seed}, {first_seed + flights - 1}] }}
""", encoding="utf-8")
    return path


def campaign(flights: int, workers: int, first_seed: int) -> dict[str, Any]:
    """Fly `flights` seeds as one campaign on `workers` local Ray workers."""
    with tempfile.TemporaryDirectory() as tmp:
        c = load_campaign(_campaign_file(Path(tmp), flights, first_seed))
        t0 = time.perf_counter()
        with ray_session(None, workers) as ray:
            t_up = time.perf_counter()
            noop = ray.remote(num_cpus=1)(lambda: None)
            ray.get([noop.remote() for _ in range(workers)])  # workers started
            trips = []
            for _ in range(50):
                t = time.perf_counter()
                ray.get(noop.remote())
                trips.append(time.perf_counter() - t)
            t_run = time.perf_counter()
            out = run_campaign(c, Path(tmp) / "out", ray, quiet=True)
            t_done = time.perf_counter()
        t_down = time.perf_counter()
    rows = out.rows
    ok = [r for r in rows if r["status"] == "ok"]
    return {
        "flights": len(rows), "ok": len(ok), "workers": workers,
        "wall_s": t_done - t_run, "start_s": t_up - t0, "stop_s": t_down - t_done,
        "per_min": 60.0 * len(rows) / (t_done - t_run),
        "run_cpu_s": sum(r["cpu_s"] for r in rows), "run_wall_s": sum(r["wall_s"] for r in rows),
        "sim_s": sum(r["sim_s"] for r in ok),
        "noop_ms": 1e3 * statistics.median(trips),
        "rms_median_cm": 100 * statistics.median(r["rms_error_m"] for r in ok) if ok else 0.0,
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--flights", type=int, default=200)
    ap.add_argument("--scaling-flights", type=int, default=40)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--speed-only", action="store_true", help="part 1 alone")
    args = ap.parse_args()

    if not args.speed_only:
        print(f"1. lockstep flight: {HOLD_S:.0f} s hold at 1 m, 1 vehicle, full sensors, 40 Hz "
              "streams, mocap + truth (best of 2)")
    print(f"   {native.describe()}:")
    for record in (False, True):
        sim_s, cpu_s, rms = lockstep_speed(record)
        print(f"   recording {'on ' if record else 'off'}: {sim_s:.1f} simulated s in "
              f"{cpu_s:.2f} CPU s = {sim_s / cpu_s:.0f}x (goal 100x); hold RMS {rms * 100:.2f} cm")
    if args.speed_only:
        return
    if native.REASON is None:
        sys.stdout.flush()
        subprocess.run([sys.executable, __file__, "--speed-only"], check=True,
                       env={**os.environ, native.ENV_SWITCH: "0"})

    big = campaign(args.flights, args.workers, first_seed=1)
    print(f"2. campaign: {big['flights']} seeded {HOLD_S:.0f} s hold flights on "
          f"{big['workers']} workers: {big['wall_s']:.1f} s wall = {big['per_min']:.0f} "
          f"flights/min (goal 100); {big['ok']} ok, median hold RMS {big['rms_median_cm']:.2f} "
          f"cm; Ray start {big['start_s']:.1f} s, stop {big['stop_s']:.1f} s; "
          f"{big['sim_s'] / big['wall_s']:.0f} simulated s per wall s")

    one = campaign(args.scaling_flights, 1, first_seed=1001)
    two = campaign(args.scaling_flights, 2, first_seed=1001)
    print(f"3. scaling, {args.scaling_flights} flights: 1 worker {one['per_min']:.0f} "
          f"flights/min, 2 workers {two['per_min']:.0f} flights/min = "
          f"{two['per_min'] / one['per_min']:.2f}x (goal 1.8x)")

    extra = (one["wall_s"] - one["run_cpu_s"]) / one["flights"]
    inside = (one["run_wall_s"] - one["run_cpu_s"]) / one["flights"]
    print(f"4. Ray overhead: no-op task round trip {one['noop_ms']:.2f} ms; 1-worker campaign "
          f"wall per run beyond the run's own CPU {extra * 1e3:.0f} ms (of which "
          f"{inside * 1e3:.0f} ms inside the run: waiting for a CPU), per run CPU "
          f"{one['run_cpu_s'] / one['flights']:.2f} s")


if __name__ == "__main__":
    install()  # lockstep flights fly the bundled SITL in this process
    main()
