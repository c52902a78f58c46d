"""What a radio fade would cost at each moment of a steady hold: the blind touchdown per tick.

Flies `quadgcs fly` (a 60 s hold at 1 m) in lockstep on the bundled SITL, recorded, per seed and
profile. For every tick of the hold from 10 s on it takes the command the station sent (the
altitude controller's acceleration, below hover when negative), the estimate's height above the
rest height and vertical speed, and asks `gcs.supervisor.envelope.blind_touchdown` how fast the
vehicle would meet the floor if the uplink died right then and the firmware flew that command
blind until its failsafe (the dialect's `blind_s`) and then braked. That is the risk the blind
envelope bounds (0.8 m/s for a steady hold) and opens for a climb the hold must stop, which a
steady hold's own wobble can look like.

Prints per profile: ticks, the share whose blind touchdown would exceed 0.9 and 1.0 m/s, the
worst, and the most downward command; once from the station's estimate (what the bound itself
uses: heights above the lowest estimate of the flight, a few mm off the supervisor's rest height,
which moves a touchdown at the 0.8 m/s bound by about 0.01 m/s) and once from the SITL's truth
(height above the floor and vertical speed, as the fault suite scores a fade).

    .venv/bin/python bench/blind_risk.py [--seeds 1-8] [--profiles apm25,copter4]
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from bench.open_loop import seed_range
from firmware_link.records import Dialect
from gcs.commands.fly import fly_session
from gcs.control.altitude_controller import AltitudeControllerParams
from gcs.flight import FlightPlan
from gcs.lockstep_session import LockstepSession
from gcs.station.session import SessionOptions
from gcs.supervisor.envelope import blind_touchdown
from gcs.supervisor.params import SupervisorParams
from lab.lockstep import install
from logs import open_recording

SETPOINT_M = 1.0
HOLD_S = 60.0
SKIP_S = 10.0  # of the hold: the take-off's end is not a steady hold


def hold_ticks(profile: str, seed: int, tmp: Path) -> dict[str, np.ndarray]:
    """Per hold tick: the commanded acceleration (m/s², up), and the height above the floor (m)
    and vertical speed (m/s) by the estimate and by truth."""
    out = tmp / f"{profile}-{seed}.mcap"
    options = SessionOptions(command="fly", profile=profile, seed=seed, record=True,
                             output=out, fix_failsafe=True)
    with LockstepSession(options) as session:
        fly_session(session, FlightPlan(alt_m=SETPOINT_M, hold_s=HOLD_S), pilot_signals=False)
    estimates: dict[int, dict] = {}
    control: list[tuple[int, dict]] = []
    truth: list[tuple[int, float, float]] = []
    for topic, log_ns, data in open_recording(out).raw_messages():
        if topic == "/gcs/estimate":
            estimates[log_ns] = json.loads(data)
        elif topic == "/gcs/alt_controller":
            control.append((log_ns, json.loads(data)))
        elif topic == "/vehicle/sim_truth":
            t = json.loads(data)
            truth.append((log_ns, -t["pos_n"]["z"], -t["vel_n"]["z"]))
    rest = min(e["alt_m"] for e in estimates.values())
    steady = [(ns, estimates[ns], c) for ns, c in control
              if ns in estimates and abs(c["setpoint_m"] - SETPOINT_M) < 1e-6]
    steady = steady[int(SKIP_S / 0.025):]
    ns = np.array([n for n, _, _ in steady], dtype=float)
    t_ns, t_h, t_w = (np.array(x, dtype=float) for x in zip(*truth, strict=True))
    return {"est_h": np.array([e["alt_m"] - rest for _, e, _ in steady]),
            "est_w": np.array([e["vel_mps"] for _, e, _ in steady]),
            "true_h": np.interp(ns, t_ns, t_h - t_h.min()),
            "true_w": np.interp(ns, t_ns, t_w),
            "a": np.array([c["accel_cmd_mps2"] for _, _, c in steady])}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", default="1-8", help="SITL seeds, FIRST-LAST (default 1-8)")
    ap.add_argument("--profiles", default="apm25,copter4", help="comma-separated profiles")
    args = ap.parse_args()
    seeds = seed_range(args.seeds)
    print(f"lockstep, {HOLD_S:g} s hold at {SETPOINT_M} m from {SKIP_S:g} s in, seeds "
          f"{seeds[0]}-{seeds[-1]}: the touchdown if the uplink died at each tick")
    print(f"{'profile':8} {'from':6} {'ticks':>7} {'> 0.9 m/s':>10} {'> 1.0 m/s':>10} "
          f"{'worst m/s':>10} {'most down m/s2':>15}")
    with tempfile.TemporaryDirectory() as tmp:
        for profile in args.profiles.split(","):
            # the envelope the station's own supervisor flies with (the hold's default gains)
            blind = SupervisorParams.for_dialect(Dialect(profile)).blind(
                AltitudeControllerParams().gains.out_max)
            parts = [hold_ticks(profile, s, Path(tmp)) for s in seeds]
            ticks = {k: np.concatenate([p[k] for p in parts]) for k in parts[0]}
            a = ticks["a"]
            for source in ("est", "true"):
                h, w = ticks[f"{source}_h"], ticks[f"{source}_w"]
                down = np.array([blind_touchdown(hi, wi, max(-ai, 0.0), blind)
                                 for hi, wi, ai in zip(h, w, a, strict=True)])
                print(f"{profile:8} {source:6} {down.size:7d} {100 * np.mean(down > 0.9):9.2f}% "
                      f"{100 * np.mean(down > 1.0):9.2f}% {down.max():10.2f} {a.min():15.2f}")
    return 0


if __name__ == "__main__":
    install()  # lockstep flights fly the bundled SITL in this process
    sys.exit(main())
