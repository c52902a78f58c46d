"""`quadgcs sitl`: run the bundled SITL (`python -m sitl`) as a separate program.

The station never imports the SITL: this subcommand re-executes `python -m sitl` with the same
flags, so its stdout contract and exit codes are exactly the SITL's own.
"""

from __future__ import annotations

import argparse
import signal
import subprocess
import sys

FORWARDED: tuple[tuple[str, str], ...] = (
    ("world", "--world"),
    ("tcp", "--tcp"),
    ("udp", "--udp"),
    ("vehicles", "--vehicles"),
    ("speedup", "--speedup"),
    ("profile", "--profile"),
    ("seed", "--seed"),
    ("signing_key", "--signing-key"),
    ("mocap_port", "--mocap-port"),
    ("copter4_version", "--copter4-version"),
    ("truth_port", "--truth-port"),
    ("rc_input", "--rc-input"),
    ("home_distance", "--home-distance"),
)


def register(subparsers: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add the `sitl` subcommand."""
    p: argparse.ArgumentParser = subparsers.add_parser(
        "sitl", help="run the bundled simulated vehicle(s) behind MAVLink endpoints"
    )
    # No defaults here: a flag not given is not passed on, and the SITL's own default holds
    # (the help says which); the SITL checks the values and answers with its own message.
    p.add_argument("--world", metavar="FILE", help="world TOML file (default: empty 6 m room)")
    p.add_argument("--tcp", metavar="PORT",
                   help="TCP port of vehicle 1; vehicle i gets PORT+10*(i-1); 0 = OS-chosen "
                        "(default 5760)")
    p.add_argument("--udp", metavar="HOST:PORT", help="also send MAVLink to HOST:PORT (UDP)")
    p.add_argument("--serial", action="store_true",
                   help="also open a pseudo-terminal serial port (115200 baud)")
    p.add_argument("--vehicles", metavar="N", help="how many vehicles, 1..5 (default 1)")
    p.add_argument("--speedup", metavar="K",
                   help="run the simulation K times faster than real time (default 1)")
    p.add_argument("--profile", choices=["apm25", "copter4"],
                   help="firmware to behave as: apm25 = ArduCopter 3.2.1 (MAVLink 1), copter4 "
                        "= ArduCopter 4.x (MAVLink 2) (default apm25)")
    p.add_argument("--seed", metavar="N", help="seed of the sensor noise (default 0)")
    p.add_argument("--signing-key", metavar="FILE",
                   help="MAVLink 2 signing key file (copter4 only; default: no signing)")
    p.add_argument("--no-noise", action="store_true",
                   help="perfect sensors (tests of the physics only)")
    p.add_argument("--realistic-boot", action="store_true",
                   help="copter4: refuse to arm for the real ≈24 s after boot (default ≈3 s)")
    p.add_argument("--copter4-version", choices=["4.6", "4.7"],
                   help="copter4 parameter names: 4.7 (MAV_GCS_SYSID, MAVn_*) or 4.6 for any "
                        "4.x before 4.7 (SYSID_MYGCS, SRn_*) (default 4.7)")
    p.add_argument("--rc-input", choices=["absent", "min", "mid"],
                   help="the vehicles' RC receiver: min = present, throttle at 1000 µs (the real "
                        "simulators' default), mid = throttle at 1500 µs, absent = none (the "
                        "radio failsafe acts when the overrides stop) (default min)")
    p.add_argument("--gps", action=argparse.BooleanOptionalAction, default=None,
                   help="a GPS fix with home set, as the real simulators have: RTL flies and "
                        "3.2.1's GCS failsafe climbs to RTL_ALT (default: no fix, as indoors)")
    p.add_argument("--home-distance", metavar="M",
                   help="how far from home the GPS puts the vehicle (default 3 m; over 2 m, "
                        "3.2.1's GCS failsafe picks RTL, else LAND)")
    p.add_argument("--truth-port", metavar="PORT",
                   help="open a ground-truth TCP endpoint for scoring (0 = OS-chosen; default: "
                        "none)")
    p.add_argument("--mocap-port", metavar="PORT",
                   help="motion-capture TCP port when the world has it on (default 5750; "
                        "OS-chosen with --tcp 0)")
    p.set_defaults(func=run)


def sitl_argv(args: argparse.Namespace) -> list[str]:
    """The `python -m sitl` command line for these arguments."""
    argv = [sys.executable, "-m", "sitl"]
    for attr, flag in FORWARDED:
        value = getattr(args, attr, None)
        if value is not None:
            argv += [flag, str(value)]
    if args.serial:
        argv.append("--serial")
    if args.no_noise:
        argv.append("--no-noise")
    if getattr(args, "realistic_boot", False):
        argv.append("--realistic-boot")
    gps = getattr(args, "gps", None)
    if gps is not None:
        argv.append("--gps" if gps else "--no-gps")
    return argv


def run(args: argparse.Namespace) -> int:
    """Run the SITL in the foreground; SIGINT/SIGTERM are passed on; its exit code is ours."""
    proc = subprocess.Popen(sitl_argv(args))

    def forward(sig: int, _frame: object) -> None:
        proc.send_signal(sig)

    previous = {s: signal.signal(s, forward) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        return proc.wait()
    finally:
        for s, handler in previous.items():
            signal.signal(s, handler)
