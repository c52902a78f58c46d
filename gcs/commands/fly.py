"""`quadgcs fly`: take off, hold an altitude under the PC's 25 ms loop, land, print a summary.

With no `--connect` it starts the bundled SITL and flies that. `--json` prints one JSON object;
`--live` prints a telemetry line a few times per second while flying.

The pilot's switches at the terminal: Ctrl-C (or SIGTERM) ends the flight by landing the vehicle
(LAND, confirmed) before letting go; Ctrl-\\ (SIGQUIT) is the kill switch: throttle minimum and
disarm, repeated until the vehicle says it is disarmed.
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import ipaddress
import json
import math
import signal
import socket
import sys
from pathlib import Path
from typing import Any, Protocol, runtime_checkable

from firmware_link import FirmwareInfo, LinkError, parse_connection_string
from gcs.clock import Clock
from gcs.commands._vehicle_args import add_vehicle_arguments, session_options
from gcs.config import HoldMode, load_config
from gcs.errors import FlightFailed, UsageError
from gcs.flight import FlightPlan, FlightRunner, FlightSummary, Phase
from gcs.station.session import StationSession
from gcs.station.station import StationSnapshot


@runtime_checkable
class Stepped(Protocol):
    """A session whose simulated time moves only when it is ticked (a lockstep session)."""

    def tick(self) -> None: ...


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add the `fly` subcommand."""
    p = sub.add_parser("fly", help="hold an altitude under the PC controller, then land",
                       description=__doc__)
    add_vehicle_arguments(p)
    p.add_argument("--alt", type=float, default=1.0, help="hold altitude, m (default 1.0)")
    p.add_argument("--hold", type=float, default=30.0, help="hold time, s (default 30)")
    p.add_argument("--step", type=float, default=0.0,
                   help="after the hold, step the setpoint by this many m and score it")
    plan = FlightPlan()
    p.add_argument("--step-watch", type=float, default=plan.step_observe_s, metavar="S",
                   help="watch the step this long before landing; a step still outside its "
                        f"band then never settled (default {plan.step_observe_s:g})")
    p.add_argument("--step-band", type=float, default=plan.step_band_m, metavar="M",
                   help="the step has settled once its altitude stays within this many m of "
                        f"the new setpoint (default {plan.step_band_m:g})")
    p.add_argument("--speedup", type=float, default=1.0,
                   help="run the bundled SITL and the loop this many times faster (default 1); "
                        "with --connect only for a simulator on this machine started with the "
                        "same speed-up")
    p.add_argument("--takeoff-delay", type=float, default=0.0, metavar="S",
                   help="stay armed on the floor this long before taking off (default 0)")
    p.add_argument("--arm-timeout", type=float, default=plan.arm_timeout_s, metavar="S",
                   help="ask the vehicle to arm again, showing the firmware's refusal, until "
                        f"this long after the first request (default {plan.arm_timeout_s:g}; "
                        "4.x's pre-arm refuses for ~24 s after boot)")
    p.add_argument("--lockstep", action="store_true",
                   help="fly the bundled SITL in this process on simulated time, as fast as the "
                        "CPU allows and the same flight for the same --seed (no --connect)")
    p.add_argument("--hold-mode", choices=[m.value for m in HoldMode], default=None,
                   help="climb-rate: the PC asks climb rates of the vehicle's ALT_HOLD (the last "
                   "override flown blind holds the height); throttle: the PC's PID flies the "
                   "throttle in STABILIZE (thesis ch. 7). Default: the --config file's "
                   "hold_mode, else throttle")
    p.add_argument("--faults", type=Path, metavar="FILE",
                   help="with --lockstep: inject this fault schedule (TOML, see "
                        "docs/fault-search.md); the same --seed and file replay the flight")
    p.add_argument("--json", action="store_true", help="print the summary as one JSON object")
    p.add_argument("--live", action="store_true", help="print telemetry lines while flying")
    p.set_defaults(func=run)


ABSURD_RMS_M = 0.5
"""A hold error beyond this is a vehicle that did not do what it was told."""


def _plan(args: argparse.Namespace) -> FlightPlan:
    try:
        return FlightPlan(alt_m=args.alt, hold_s=args.hold, step_m=args.step,
                          step_observe_s=args.step_watch, step_band_m=args.step_band,
                          takeoff_delay_s=args.takeoff_delay, arm_timeout_s=args.arm_timeout)
    except ValueError as exc:
        raise UsageError(f"--alt/--hold/--step/--step-watch/--step-band/--arm-timeout: "
                         f"{exc}") from None


class LivePrinter:
    """Prints a telemetry line at most every `period_s` of the station clock."""

    def __init__(self, clock: Clock, period_s: float = 0.25) -> None:
        self.clock = clock
        self.period_s = period_s
        self._next = -math.inf

    def __call__(self, snap: StationSnapshot, phase: Phase) -> None:
        now = self.clock.now_s()
        if now < self._next:
            return
        self._next = now + self.period_s
        est = snap.estimate
        truth = f"{-snap.truth.pos_n[2]:6.3f}" if snap.truth else "   n/a"
        att = snap.attitude
        print(
            f"{phase.value:8s} alt {est.alt_m if est else math.nan:6.3f} m "
            f"(truth {truth}) set {snap.alt_setpoint_m or 0.0:5.2f} m "
            f"vz {est.vel_mps if est else math.nan:+5.2f} m/s "
            f"thr {snap.command.throttle_us} us "
            f"roll {math.degrees(att.roll_rad) if att else 0.0:+5.1f} "
            f"pitch {math.degrees(att.pitch_rad) if att else 0.0:+5.1f} deg "
            f"{'ARMED' if snap.armed else 'disarmed'}{' LINK LOST' if snap.link_lost else ''}",
            flush=True,
        )


def _metres(x: float) -> float | None:
    """A score for JSON: rounded to 0.1 mm, None when there was nothing to score."""
    return round(x, 4) if math.isfinite(x) else None


def _summary_dict(s: FlightSummary, recording: str | None,
                  firmware: FirmwareInfo) -> dict[str, Any]:
    d: dict[str, Any] = {
        "rms_error_m": _metres(s.rms_error_m),
        "max_error_m": _metres(s.max_error_m),
        "mean_error_m": _metres(s.mean_error_m),
        "std_error_m": _metres(s.std_error_m),
        "error_source": s.error_source,
        "truth_coverage": round(s.truth_coverage, 3),
        "truth_rate_hz": round(s.truth_rate_hz, 1),
        "jitter_p50_ms": round(s.jitter_p50_ms, 3),
        "jitter_p99_ms": round(s.jitter_p99_ms, 3),
        "compute_p99_ms": round(s.compute_p99_ms, 3),
        "overruns": s.overruns,
        "ticks": s.ticks,
        "rx_messages": s.rx_messages,
        "lost_messages": s.lost_messages,
        "corrupted_frames": s.corrupted,
        "hover_throttle": round(s.hover_throttle, 4),
        "dialect": firmware.dialect.value,
        "firmware": firmware.name,
        "firmware_source": firmware.source,
        "recording": recording,
    }
    if s.estimator is not None:
        d["estimator"] = dataclasses.asdict(s.estimator)
    if s.step is not None:
        d["step"] = {
            "step_m": s.step.step_m,
            "overshoot_pct": round(s.step.overshoot_pct, 2),
            "settle_time_s": s.step.settle_time_s if math.isfinite(s.step.settle_time_s)
            else None,
            "band_m": s.step.band_m,
        }
    return d


def _print_summary(d: dict[str, Any]) -> None:
    source = d["error_source"]
    if source == "none":
        print("altitude hold: not scored (no ground truth and no estimate during the hold)")
    else:
        against = (f"vs truth ({d['truth_coverage'] * 100:.0f} % of the hold, "
                   f"{d['truth_rate_hz']:.0f} Hz)" if source == "truth"
                   else "vs the station's own estimate (no truth: the controller's error only)")
        print(f"altitude hold {against}: RMS {d['rms_error_m'] * 100:.2f} cm = bias "
              f"{d['mean_error_m'] * 100:+.2f} cm, std {d['std_error_m'] * 100:.2f} cm; "
              f"worst {d['max_error_m'] * 100:.1f} cm")
    if "step" in d:
        st = d["step"]
        settle = "never" if st["settle_time_s"] is None else f"{st['settle_time_s']:.2f} s"
        print(f"step {st['step_m']:+.2f} m: overshoot {st['overshoot_pct']:.1f} %, "
              f"settled within ±{st['band_m'] * 100:.0f} cm after {settle}")
    print(f"loop: jitter p50 {d['jitter_p50_ms']:.3f} ms, p99 {d['jitter_p99_ms']:.3f} ms, "
          f"compute p99 {d['compute_p99_ms']:.3f} ms, overruns {d['overruns']} "
          f"of {d['ticks']} ticks")
    print(f"firmware {d['firmware']} (identified by {d['firmware_source'] or 'nothing'})")
    print(f"link ({d['dialect']}): {d['rx_messages']} messages received, "
          f"{d['lost_messages']} lost, {d['corrupted_frames']} corrupted")
    if "estimator" in d:
        e = d["estimator"]
        print(f"estimator set aside: {e['sonar_rejected']} sonar readings (gate), "
              f"{e['imu_repeats']} IMU samples received twice, {e['implausible_times']} "
              f"stamped ahead of the station's clock; {e['late_bursts']} late bursts "
              "integrated at their own times")
    print(f"learned hover throttle {d['hover_throttle']:.3f}")
    if "hold_mode" in d:
        print(f"hold mode: {d['hold_mode']}")
    if "forward" in d:
        f = d["forward"]
        print(f"forward {', '.join(f['endpoints'])}: {f['to_stations']} frames out, "
              f"{f['to_vehicle']} in; refused: {f['refused_overrides']} RC overrides, "
              f"{f['refused_streams']} stream-rate requests, {f['refused_silent']} while "
              f"silent, {f['refused_unsigned']} unsigned")
    if "live_checks" in d:
        print(d["live_checks"])
    print(f"recording: {d['recording'] or 'off'}")


def _simulator_url(url: str) -> bool:
    """A connection that can only reach a program on this machine (loopback, a pty): the only
    kind a sped-up clock may fly, since a real vehicle answers in real time."""
    try:
        spec = parse_connection_string(url)
    except LinkError:
        return False
    if spec.device:
        return spec.device.startswith("/dev/pts/")
    try:
        return ipaddress.ip_address(socket.gethostbyname(spec.host)).is_loopback
    except (OSError, ValueError):
        return False


def _on_sigterm(signum: int, frame: object) -> None:
    # a terminated flight unwinds like Ctrl-C: the session lands the vehicle before letting go
    raise KeyboardInterrupt(f"signal {signum}")


def fly(args: argparse.Namespace) -> dict[str, Any]:
    """Run the whole flight; return the summary dict (the CLI prints it). FlightFailed (exit 3)
    when the flight did not go as commanded; leaving the session lands a flying vehicle."""
    plan = _plan(args)
    if args.speedup != 1.0 and args.connect is not None and not _simulator_url(args.connect):
        raise UsageError("--speedup applies to a simulator on this machine only (loopback or a "
                         "pseudo-terminal); a vehicle at --connect flies in real time")
    options = session_options(args, "fly")
    config = load_config(options.config)
    if getattr(args, "hold_mode", None) is not None:
        config = dataclasses.replace(config, hold_mode=HoldMode(args.hold_mode))
    faults = getattr(args, "faults", None)
    if faults is not None and not getattr(args, "lockstep", False):
        raise UsageError("--faults: a fault schedule is flown on the bundled SITL in lockstep; "
                         "add --lockstep")
    if getattr(args, "lockstep", False):
        from gcs.lockstep_session import LockstepSession

        session: StationSession = LockstepSession(
            options, config=config,
            faults=None if faults is None else {"schedule": faults, "schedule_flight": plan})
    else:
        session = StationSession(options, config=config)
    with session:
        return fly_session(session, plan, live=args.live)


def fly_session(session: StationSession, plan: FlightPlan, live: bool = False,
                pilot_signals: bool = True) -> dict[str, Any]:
    """Fly `plan` on an open session's first vehicle (a lockstep session runs its ticks from
    here); the summary dict, or FlightFailed. `pilot_signals`: the terminal's SIGTERM and
    SIGQUIT land and kill this flight (a campaign's worker leaves its process's own)."""
    v = session.first
    lockstep = isinstance(session, Stepped)
    with contextlib.suppress(ValueError):  # not the main thread (tests): no handlers
        if pilot_signals:
            signal.signal(signal.SIGTERM, _on_sigterm)
            signal.signal(signal.SIGQUIT, lambda _n, _f: v.station.kill())
    if not lockstep:
        v.station.start()
    printer = LivePrinter(session.clock) if live else None
    runner = FlightRunner(v.station, plan, printer,
                          idle=session.tick if isinstance(session, Stepped) else None,
                          sysid=v.sysid)
    path = str(v.recorder.path) if v.recorder is not None else None
    try:
        runner.fly()
    except FlightFailed as exc:
        snap = v.station.snapshot(loop_stats=False)
        raise FlightFailed(f"{exc}; link down {snap.link_down_s:.1f} s; recording "
                           f"{path or 'off'}") from None
    d = _summary_dict(runner.summary(v.truth_series()), path, v.link.firmware)
    d["link_down_s"] = round(v.station.snapshot(loop_stats=False).link_down_s, 3)
    d["hold_mode"] = v.station.config.hold_mode.value
    d["live_checks"] = v.station.live_check.summary()[1]
    d["status"] = "ok"
    if session.forwarder is not None:
        d["forward"] = dataclasses.asdict(session.forwarder.stats)
    rms = d.get("rms_error_m")
    if not isinstance(rms, float) or not math.isfinite(rms) or rms > ABSURD_RMS_M:
        raise FlightFailed(f"hold error {rms} m is not a flight that went as commanded "
                           f"(over {ABSURD_RMS_M} m or unknown); recording {path or 'off'}")
    return d


def run(args: argparse.Namespace) -> int:
    """CLI entry: fly, then print the summary (text or JSON)."""
    try:
        d = fly(args)
    except FlightFailed as exc:
        if args.json:
            json.dump({"status": "failed", "reason": str(exc)}, sys.stdout)
            print()
        raise
    if args.json:
        json.dump(d, sys.stdout)
        print()
    else:
        _print_summary(d)
    return 0
