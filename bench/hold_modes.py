"""The two PC hold modes against the SITL's onboard ALT_HOLD, and what each does flown blind.

Lockstep flights on the bundled SITL (simulated clock, seeded; the pre-flight's failsafe fix as
`quadgcs fly --fix-failsafe`), per profile and seed:
- hold quality, scored against the SITL's truth at 50 Hz (`gcs.scoring`): RMS against the set
  point, bias, std about the mean, worst; for the direct-throttle hold (STABILIZE, thesis ch. 7),
  the climb-rate hold (the PC's loop asking climb rates of the firmware's ALT_HOLD) and the
  onboard ALT_HOLD alone (taken off by the climb-rate hold, then the station's loop off and the
  sticks centred: mid-stick holds, no PC loop). The issue's goal: hold std <= 1.5x onboard,
  RMS <= 2 cm. Take-off overshoot over the set point (truth) for the two PC modes.
- `--fades`: the hold at 1 m, then 15 s of radio fade ("up": the station's frames lost;
  "both"), the receiver at minimum: the most the vehicle rises over the hold's set point (the
  SITL's own ALT_HOLD wanders about it), the fastest it sinks within 0.3 m of the floor
  (touch-down), and when it disarms. Bounds: rise <= 0.3 m, touch-down <= 1.0 m/s, disarmed
  within 20 s.

Prints numbers; asserts nothing. Run it niced: it takes a core for minutes.

    nice -n 10 .venv/bin/python bench/hold_modes.py [--seeds 20] [--hold 20] [--alt 1.0]
        [--profiles apm25,copter4] [--modes throttle,climb-rate,onboard] [--fades 10]
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import statistics
import sys
from typing import Any

from firmware_link.records import FlightMode
from gcs.config import HoldMode, StationConfig
from gcs.control.attitude import yaw_from_quat
from gcs.control.position_controller import PositionSetpoint
from gcs.flight import FlightPlan, FlightRunner, Phase
from gcs.lockstep_session import LockstepSession
from gcs.scoring import score_hold
from gcs.station.session import SessionOptions
from lab.lockstep import install
from sitl.autopilot import AutopilotOptions
from sitl.autopilot.profile import RcInput
from sitl.world import default_world

FADE_AT_S = 40.0
FADE_S = 15.0


def _options(profile: str, seed: int) -> SessionOptions:
    return SessionOptions(command="fly", profile=profile, seed=seed, record=False,
                          fix_failsafe=True)


def _config(mode: HoldMode) -> StationConfig:
    return dataclasses.replace(StationConfig(), hold_mode=mode)


def _overshoot_pct(runner: FlightRunner, truth: Any, alt_m: float) -> float:
    hold = [s.t_s for s in runner.samples if s.phase is Phase.HOLD]
    if truth is None or not hold:
        return math.nan
    part = truth.between(runner.samples[0].t_s, hold[0])
    return max(0.0, (float(max(part.alt_m)) - alt_m) / alt_m * 100.0)


def pc_hold(profile: str, seed: int, mode: HoldMode, alt_m: float, hold_s: float) -> dict[str, Any]:
    """One `fly` in lockstep; hold numbers (cm) and the take-off's overshoot."""
    s = LockstepSession(_options(profile, seed), config=_config(mode))
    with s:
        v = s.first
        runner = FlightRunner(v.station, FlightPlan(alt_m=alt_m, hold_s=hold_s), idle=s.tick)
        runner.fly()
        truth = v.truth_series()
        summ = runner.summary(truth)
        over = _overshoot_pct(runner, truth, alt_m)
    return {"rms": summ.rms_error_m * 100, "mean": summ.mean_error_m * 100,
            "std": summ.std_error_m * 100, "max": summ.max_error_m * 100, "over": over}


def onboard_hold(profile: str, seed: int, alt_m: float, hold_s: float) -> dict[str, Any]:
    """Take off with the climb-rate hold, then the PC loop off and the sticks centred: the
    firmware's ALT_HOLD alone; scored against `alt_m` on truth."""
    s = LockstepSession(_options(profile, seed), config=_config(HoldMode.CLIMB_RATE))
    with s:
        v = s.first
        st = v.station
        runner = FlightRunner(st, FlightPlan(alt_m=alt_m, hold_s=0.1), idle=s.tick)
        runner.arm()
        runner.phase = Phase.ARMED
        runner.launch.ask_takeoff(alt_m, 0.5)
        runner.phase = Phase.TAKEOFF
        runner.wait("take-off", lambda sn: sn.estimate is not None
                    and abs(sn.estimate.alt_m - alt_m) < 0.05, alt_m / 0.5 + 20.0)
        runner.phase = Phase.SETTLE
        runner.pause(4.0)
        runner.phase = Phase.DONE  # from here the PC flies nothing
        st.alt_hold(False)
        runner.pause(0.1)
        # the pilot's stick meets the throttle the hold left (the supervisor's gate), then
        # centres: mid-stick is "hold this height"
        held = st.snapshot(loop_stats=False).command.throttle_us
        st.set_sticks(1500, 1500, 1500, held)
        runner.pause(0.1)
        st.set_sticks(1500, 1500, 1500, 1500)
        runner.pause(2.0)
        if st.snapshot(loop_stats=False).command.throttle_us != 1500:
            raise RuntimeError("the sticks did not centre")
        t0 = st.clock.now_s()
        runner.pause(hold_s)
        t1 = st.clock.now_s()
        hold = [x for x in runner.samples if t0 <= x.t_s <= t1]
        score = score_hold([x.t_s for x in hold], [alt_m] * len(hold),
                           [x.est_alt_m for x in hold], v.truth_series())
        runner.expected_modes.add(FlightMode.LAND)
        st.set_mode(FlightMode.LAND)
        runner.wait("disarm in LAND", lambda sn: not sn.armed, 60.0)
    e = score.errors
    return {"rms": e.rms_m * 100, "mean": e.mean_m * 100, "std": e.std_m * 100,
            "max": e.max_m * 100, "over": math.nan}


def fade(profile: str, seed: int, mode: HoldMode, way: str, alt_m: float = 1.0) -> dict[str, Any]:
    """Hold `alt_m`, then a 15 s fade `way` at FADE_AT_S: rise, touch-down speed, disarm time."""
    room = default_world()
    world = dataclasses.replace(room, autopilot=AutopilotOptions(rc_input=RcInput.MIN),
                                room_min_n=(*room.room_min_n[:2], -30.0))
    faults = {"fade": way, "fade_start_s": FADE_AT_S, "fade_s": FADE_S}
    rows: list[tuple[float, float, float, bool]] = []
    s = LockstepSession(_options(profile, seed), world=world, config=_config(mode),
                        faults=faults)
    with s:
        st = s.first.station
        sim = s.sitl.sitl.sim  # type: ignore[attr-defined]  # the lockstep SITL's truth
        clock = s.clock

        def sample(*_: object) -> None:
            tr = sim.vehicle(1).vehicle.truth
            rows.append((clock.now_s(), -tr.pos_n[2], -tr.vel_n[2],
                         sim.vehicle(1).autopilot.state.armed))

        st.add_listener(sample)
        st.request_arm(wait_s=30.0)
        while clock.now_s() < 8.0 or not rows or not rows[-1][3]:
            st.run_tick()
            if clock.now_s() > 60.0:
                return {"error": "did not arm"}
        st.alt_hold(True, alt_m, rate_mps=0.5)
        _hold_position(st)
        while clock.now_s() < FADE_AT_S + FADE_S + 25.0:
            st.run_tick()
    at = [r for r in rows if r[0] >= FADE_AT_S]
    if not at:
        return {"error": "flight ended before the fade"}
    h0 = at[0][1]  # the SITL's own ALT_HOLD wanders about the hold: the rise is the hold's
    low = [-vz for _, h, vz, armed in at if h < 0.3 and armed]
    off = [t for t, *_, armed in at if not armed]
    return {"rise": max(h for _, h, _, _ in at) - alt_m, "touchdown": max(low, default=0.0),
            "disarm_s": off[0] - FADE_AT_S if off else math.inf, "h0": h0}


def _hold_position(st: Any) -> None:
    """Hold the take-off spot and heading on motion capture, as `fly` does: without it the
    vehicle drifts on its attitude noise and may land on the edge of the room's box."""
    pose = st.snapshot(loop_stats=False).mocap
    if pose is not None:
        n, e, _ = pose.pos_n
        st.set_position_setpoint(PositionSetpoint(n, e, yaw_from_quat(pose.q_nb)))


def _stats(values: list[float]) -> str:
    v = [x for x in values if math.isfinite(x)]
    if not v:
        return "n/a"
    v.sort()
    return (f"median {statistics.median(v):6.2f}  p90 {v[int(0.9 * (len(v) - 1))]:6.2f}  "
            f"worst {v[-1]:6.2f}")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=20)
    ap.add_argument("--hold", type=float, default=20.0)
    ap.add_argument("--alt", type=float, default=1.0)
    ap.add_argument("--profiles", default="apm25,copter4")
    ap.add_argument("--modes", default="throttle,climb-rate,onboard")
    ap.add_argument("--fades", type=int, default=0, help="seeds of fades per profile/mode/way")
    ap.add_argument("--fade-modes", default="climb-rate")
    args = ap.parse_args(argv)
    install()  # lockstep flights fly the bundled SITL in this process
    for profile in args.profiles.split(","):
        for mode in args.modes.split(","):
            rows = []
            for seed in range(1, args.seeds + 1):
                try:
                    r = (onboard_hold(profile, seed, args.alt, args.hold) if mode == "onboard"
                         else pc_hold(profile, seed, HoldMode(mode), args.alt, args.hold))
                except Exception as exc:  # a failed flight is a number too
                    print(f"  {profile} {mode} seed {seed}: FAILED {exc}", flush=True)
                    continue
                rows.append(r)
            if not rows:
                continue
            print(f"{profile:8s} {mode:10s} n={len(rows):3d} (cm; overshoot %)", flush=True)
            for key in ("rms", "std", "mean", "max", "over"):
                print(f"    {key:5s} {_stats([r[key] for r in rows])}", flush=True)
        for mode in args.fade_modes.split(","):
            for way in ("up", "both"):
                res = [fade(profile, seed, HoldMode(mode), way)
                       for seed in range(1, args.fades + 1)]
                ok = [r for r in res if "error" not in r]
                if not ok:
                    continue
                bad = sum(1 for r in ok if r["rise"] > 0.3 or r["touchdown"] > 1.0
                          or r["disarm_s"] > 20.0)
                print(f"{profile:8s} {mode:10s} fade {way:4s} n={len(ok)} failed-to-fly "
                      f"{len(res) - len(ok)}; outside the bounds: {bad}", flush=True)
                for key in ("rise", "touchdown", "disarm_s"):
                    print(f"    {key:9s} {_stats([r[key] for r in ok])}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
