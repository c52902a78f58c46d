"""`python -m sitl` / `quadgcs sitl`: run the bundled SITL behind MAVLink endpoints.

Stdout contract (a station parses it): one line per endpoint
`vehicle <sysid> tcp:127.0.0.1:<port>` / `vehicle <sysid> serial:<pty>` /
`vehicle <sysid> udp:<host>:<port>`, then `mocap tcp:127.0.0.1:<port>` when motion capture is
on, then `ready`. Everything else goes to stderr. SIGINT/SIGTERM end it cleanly (exit 0).
Expected errors end in one line on stderr: exit 2 for bad input, 1 for run-time failures.
"""

from __future__ import annotations

import argparse
import dataclasses
import signal
import sys
from collections.abc import Sequence
from types import FrameType

from sitl.autopilot import Profile
from sitl.autopilot.profile import COPTER4_VERSIONS, RcInput
from sitl.link.codec import SigningKeyError, load_signing_key
from sitl.link.endpoints import EndpointError
from sitl.link.server import TCP_BASE_PORT, EndpointPlan, SitlServer
from sitl.simulation import Simulation
from sitl.world import WorldError, default_world, load_world

MOCAP_DEFAULT_PORT = 5750
MAX_VEHICLES = 20


class CliError(Exception):
    """One-line error with an exit code."""

    def __init__(self, message: str, exit_code: int) -> None:
        super().__init__(message)
        self.exit_code = exit_code


def _port(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a port number 0..65535, got {text!r}") from None
    if not 0 <= value <= 65535:
        raise argparse.ArgumentTypeError(f"expected a port number 0..65535, got {value}")
    return value


def _host_port(text: str) -> tuple[str, int]:
    host, sep, port = text.rpartition(":")
    if not sep or not host:
        raise argparse.ArgumentTypeError(f"expected HOST:PORT, got {text!r}")
    p = _port(port)
    if p == 0:
        raise argparse.ArgumentTypeError(f"expected a UDP port 1..65535, got {text!r}")
    return host, p


def _positive(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number > 0, got {text!r}") from None
    if not value > 0.0 or value != value:
        raise argparse.ArgumentTypeError(f"expected a number > 0, got {text!r}")
    return value


def _distance(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected metres >= 0, got {text!r}") from None
    if not value >= 0.0 or value == float("inf"):
        raise argparse.ArgumentTypeError(f"expected metres >= 0, got {text!r}")
    return value


def _vehicles(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected 1..{MAX_VEHICLES}, got {text!r}") from None
    if not 1 <= value <= MAX_VEHICLES:
        raise argparse.ArgumentTypeError(f"expected 1..{MAX_VEHICLES}, got {value}")
    return value


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The SITL's flags (shared with `quadgcs sitl`)."""
    parser.add_argument("--world", metavar="FILE", help="world TOML file (default: empty room)")
    parser.add_argument(
        "--tcp",
        type=_port,
        default=TCP_BASE_PORT,
        metavar="PORT",
        help="TCP port of vehicle 1; vehicle i gets PORT+10*(i-1); 0 = OS-chosen (default 5760)",
    )
    parser.add_argument(
        "--udp", type=_host_port, metavar="HOST:PORT", help="also send MAVLink to HOST:PORT (UDP)"
    )
    parser.add_argument(
        "--serial", action="store_true", help="also open a pseudo-terminal serial port (115200)"
    )
    parser.add_argument("--vehicles", type=_vehicles, default=1, metavar="N",
                        help=f"how many vehicles, 1..{MAX_VEHICLES} (default 1)")
    parser.add_argument("--speedup", type=_positive, default=1.0, metavar="K",
                        help="run the simulation K times faster than real time (default 1)")
    parser.add_argument(
        "--profile", choices=[p.value for p in Profile], default=Profile.APM25.value,
        help="firmware to behave as: apm25 = ArduCopter 3.2.1 (MAVLink 1), copter4 = "
        "ArduCopter 4.x (MAVLink 2) (default apm25)",
    )
    parser.add_argument("--seed", type=int, default=0, metavar="N",
                        help="seed of the sensor noise and biases (default 0)")
    parser.add_argument(
        "--signing-key", metavar="FILE", help="MAVLink 2 signing key (copter4 only)"
    )
    parser.add_argument("--no-noise", action="store_true", help="perfect sensors (tests only)")
    parser.add_argument(
        "--realistic-boot",
        action="store_true",
        help="copter4: refuse to arm for the real ≈24 s after boot (default ≈3 s); also "
        "[autopilot] realistic_boot in the world file",
    )
    parser.add_argument(
        "--copter4-version",
        choices=COPTER4_VERSIONS,
        help="copter4 parameter names: 4.7 (MAV_GCS_SYSID, MAVn_*; default) or 4.6 for any "
        "4.x before 4.7 (SYSID_MYGCS, SRn_*); also [autopilot] copter4_version",
    )
    parser.add_argument(
        "--rc-input",
        choices=[r.value for r in RcInput],
        help="the vehicles' RC receiver: min = present, throttle at 1000 µs (the real "
        "simulators' default and ours), mid = present, throttle at 1500 µs, absent = none "
        "(the radio failsafe acts when the overrides stop)",
    )
    parser.add_argument(
        "--no-gps",
        action="store_true",
        help="no GPS fix: RTL is refused and every RTL-like failsafe lands (default: a fix "
        "with home set, as the real simulators have)",
    )
    parser.add_argument(
        "--home-distance",
        type=_distance,
        metavar="M",
        help="how far from home the GPS puts the vehicle (default 3 m; over WPNAV_RADIUS "
        "2 m, 3.2.1's GCS failsafe picks RTL, else LAND)",
    )
    parser.add_argument(
        "--truth-port",
        type=_port,
        metavar="PORT",
        help="open a ground-truth TCP endpoint for scoring (LOCAL_POSITION_NED at 50 Hz, "
        "sysid 201; 0 = OS-chosen); printed as `truth tcp:...`",
    )
    parser.add_argument(
        "--mocap-port",
        type=_port,
        metavar="PORT",
        help="motion-capture TCP port when the world has it on (default 5750; OS-chosen with "
        "--tcp 0)",
    )


EPILOG = """\
What a ground station sees:
  autopilot       sysid 1..N, compid 1; HEARTBEAT at 1 Hz; nothing else streams until
                  REQUEST_DATA_STREAM (both profiles) or SET_MESSAGE_INTERVAL (copter4).
                  apm25 = ArduCopter 3.2.1 (MAVLink 1 only); copter4 = ArduCopter 4.x.
  stream params   SR0_* for the TCP link, SR1_* for the serial port, SR2_* for UDP
                  (copter4 4.7: MAV1_*, MAV2_*, MAV3_*).
  parameters      the real firmware's lists: 412 (3.2.1), 1364 (4.7).
  ALL stream      3.2.1: 21 types at 50/(int(50/rate)+1) Hz (25 Hz at most); 4.7: 29 types
                  at the rate asked (see sitl/README.md).
  arming          apm25: refusals COMMAND_ACK UNSUPPORTED (3), "PreArm: INS not calibrated"
                  for 3 s after boot; the ACK comes 1.9 s after the command, streams paused.
                  copter4: FAILED (4) with "Arm: ..." ("Arm: Accels inconsistent" for 3 s,
                  24 s with --realistic-boot); motors stopped 2 s after arming, then spool up
                  over MOT_SPOOL_TIME.
  RAW_IMU         acceleration in mg, rates in mrad/s (as ArduPilot sends them).
  companion       compid 158 on each vehicle link, once a GCS has spoken: six IR
                  DISTANCE_SENSOR (orientations 0,2,4,6,24,25; 51 cm = nothing in range)
                  at 10 Hz, NAMED_VALUE_FLOAT "RAD_CPS" at 5 Hz when the world has sources.
  motion capture  sysid 200, compid = tracked vehicle's sysid, ATT_POS_MOCAP at 100 Hz.
  ground truth    SIM_STATE (EXTRA1 stream, at the ATTITUDE rate), for evaluation only;
                  capped at 10 Hz on the serial port so it leaves the 115200-baud budget
                  to the control streams. No SIMSTATE (it has no altitude).
                  With --truth-port: its own endpoint, `truth tcp:...`, sysid 201, compid =
                  vehicle: LOCAL_POSITION_NED at 50 Hz, z from the floor, time_boot_ms =
                  simulated time (sitl/truth_server.py), for scoring only.
  serial port     MAVLink 1 frames (apm25) carry base payloads only, as a real v1 sender.
  failsafes       as the real firmware (sitl/README.md). apm25: FS_GCS_ENABLE 1, 5 s
                  after the last heartbeat or override while overrides are in use: RTL
                  (climbs to RTL_ALT 15 m) with GPS and home over 2 m away, else LAND;
                  overrides never lapse while a receiver is present; --rc-input absent:
                  radio failsafe 2 s after the last override. copter4: FS_GCS_ENABLE 0
                  (none); when set, FS_OPTIONS 16 keeps STABILIZE/ALT_HOLD going ("GCS
                  Failsafe - Continuing Pilot Control") with the overrides cleared:
                  throttle to the receiver's 1000 µs. Overrides lapse after
                  RC_OVERRIDE_TIME 3 s; --rc-input absent: radio failsafe after
                  RC_FS_TIMEOUT 1 s (RTL with GPS, else LAND).
"""


def build_parser() -> argparse.ArgumentParser:
    """Parser of `python -m sitl`."""
    parser = argparse.ArgumentParser(
        prog="python -m sitl",
        description="Simulated ArduCopter quadrotors speaking MAVLink.",
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    add_arguments(parser)
    return parser


def _server_from_args(args: argparse.Namespace) -> SitlServer:
    profile = Profile(args.profile)
    try:
        world = load_world(args.world) if args.world else default_world()
    except WorldError as exc:
        raise CliError(str(exc), 2) from None
    key = None
    if args.signing_key:
        if profile is not Profile.COPTER4:
            raise CliError("--signing-key: signing needs --profile copter4 (MAVLink 2)", 2)
        try:
            key = load_signing_key(args.signing_key)
        except SigningKeyError as exc:
            raise CliError(str(exc), 2) from None
    opts = world.autopilot
    try:
        options = dataclasses.replace(  # the world's options, the command line's on top
            opts,
            realistic_boot=opts.realistic_boot or args.realistic_boot,
            copter4_version=args.copter4_version or opts.copter4_version,
            rc_input=RcInput(args.rc_input) if args.rc_input else opts.rc_input,
            gps=opts.gps and not args.no_gps,
            home_distance_m=(
                opts.home_distance_m if args.home_distance is None else args.home_distance
            ),
        )
    except ValueError as exc:
        raise CliError(str(exc), 2) from None
    if args.copter4_version and profile is not Profile.COPTER4:
        raise CliError("--copter4-version: needs --profile copter4", 2)
    try:
        sim = Simulation(
            world,
            profile,
            args.vehicles,
            seed=args.seed,
            noise=not args.no_noise,
            signing_key=key,
            options=options,
        )
    except WorldError as exc:
        raise CliError(f"{args.world or 'world'}: {exc}", 2) from None
    mocap_port = None
    if world.mocap_enabled:
        if args.mocap_port is not None:
            mocap_port = args.mocap_port
        else:
            mocap_port = 0 if args.tcp == 0 else MOCAP_DEFAULT_PORT
    plan = EndpointPlan(tcp_port=args.tcp, udp=args.udp, serial=args.serial, mocap_port=mocap_port,
                        truth_port=args.truth_port)
    try:
        return SitlServer(sim, plan, speedup=args.speedup)
    except EndpointError as exc:
        raise CliError(f"cannot open endpoint: {exc.strerror}", 1) from None


def run(args: argparse.Namespace) -> int:
    """Start, print the endpoint lines and `ready`, serve until a signal."""
    try:
        server = _server_from_args(args)
    except CliError as exc:
        print(f"sitl: {exc}", file=sys.stderr, flush=True)
        return exc.exit_code

    def _on_signal(_sig: int, _frame: FrameType | None) -> None:
        server.stop()

    previous = {s: signal.signal(s, _on_signal) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        for line in server.address_lines():
            print(line, flush=True)
        print("ready", flush=True)
        server.run()
    finally:
        server.close()
        for s, handler in previous.items():
            signal.signal(s, handler)
    print(
        f"sitl: stopped at t={server.sim.t_s:.1f} s ({server.resyncs} clock resyncs)",
        file=sys.stderr,
        flush=True,
    )
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of `python -m sitl`."""
    return run(build_parser().parse_args(argv))
