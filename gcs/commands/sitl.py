"""`quadgcs sitl`: run the bundled SITL (`python -m sitl`) as a separate program.

The station never imports the SITL: this subcommand re-executes `python -m sitl` with the same
flags, so its stdout contract and exit codes are exactly the SITL's own.
"""

from __future__ import annotations

import argparse
import signal
import subprocess
import sys
from typing import Any

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
)


def register(subparsers: Any) -> None:
    """Add the `sitl` subcommand."""
    p: argparse.ArgumentParser = subparsers.add_parser(
        "sitl", help="run the bundled simulated vehicle(s) behind MAVLink endpoints"
    )
    p.add_argument("--world", metavar="FILE")
    p.add_argument("--tcp", metavar="PORT")
    p.add_argument("--udp", metavar="HOST:PORT")
    p.add_argument("--serial", action="store_true")
    p.add_argument("--vehicles", metavar="N")
    p.add_argument("--speedup", metavar="K")
    p.add_argument("--profile", choices=["apm25", "copter4"])
    p.add_argument("--seed", metavar="N")
    p.add_argument("--signing-key", metavar="FILE")
    p.add_argument("--no-noise", action="store_true")
    p.add_argument("--mocap-port", metavar="PORT")
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
