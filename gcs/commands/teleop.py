"""`quadgcs teleop`: fly and watch one vehicle from a terminal.

With no `--connect` it starts the bundled SITL. The 25 ms loop runs in its own process (see
`gcs.tui.process_backend`); the Textual app only reads views and sends intents, so a slow
terminal never stretches a tick.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from gcs.session import SessionOptions


def register(sub: argparse._SubParsersAction) -> None:
    """Add the `teleop` subcommand."""
    p = sub.add_parser("teleop", help="fly one vehicle from the terminal (TUI)",
                       description=__doc__)
    p.add_argument("--connect", metavar="URL",
                   help="vehicle link (tcp:HOST:PORT, udpin:..., /dev/ttyUSB0[,baud]); "
                        "default: start the bundled SITL")
    p.add_argument("--mocap", metavar="URL", help="motion-capture endpoint (tcp:HOST:PORT)")
    p.add_argument("--profile", choices=("apm25", "copter4"), default="apm25",
                   help="firmware profile of the bundled SITL (default apm25)")
    p.add_argument("--world", type=Path, help="world TOML for the bundled SITL")
    p.add_argument("--serial", action="store_true",
                   help="use the bundled SITL's pseudo-terminal serial port (115200 baud)")
    p.add_argument("--seed", type=int, help="seed of the bundled SITL's noise")
    p.add_argument("--config", type=Path, help="station TOML (gains, estimator, timing)")
    p.add_argument("--signing-key", type=Path, help="MAVLink 2 signing key file (ArduCopter 4.x)")
    p.add_argument("--record", action=argparse.BooleanOptionalAction, default=True,
                   help="record the flight to MCAP (default on)")
    p.add_argument("-o", "--output", type=Path, default=Path("flights"),
                   help="recording file or directory (default flights/)")
    p.set_defaults(func=run)


def options_from_args(args: argparse.Namespace) -> SessionOptions:
    """The session the flags ask for."""
    return SessionOptions(
        command="teleop", connect=args.connect, mocap=args.mocap, profile=args.profile,
        world=args.world, serial=args.serial, seed=args.seed, config=args.config,
        signing_key=args.signing_key, record=args.record, output=args.output,
    )


def run(args: argparse.Namespace) -> int:
    """Start the station process, run the app until the pilot quits, then take it all down."""
    from gcs.tui.app import make_app
    from gcs.tui.process_backend import ProcessBackend

    backend = ProcessBackend(options_from_args(args))
    try:
        make_app(backend).run()
    finally:
        backend.close()
    if backend.error is not None:
        text, code = backend.error
        print(f"quadgcs teleop: {text}", file=sys.stderr)
        return code
    return 0
