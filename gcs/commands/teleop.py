"""`quadgcs teleop`: fly and watch one vehicle from a terminal.

With no `--connect` it starts the bundled SITL. The 25 ms loop runs on its own thread; the
Textual app only reads snapshots and sends intents, so a slow terminal never stretches a tick.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from gcs.session import SessionOptions, StationSession

# No spinning before ticks: a spinning loop thread starves the UI thread of the GIL.
TUI_SPIN_S = 0.0


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
        spin_s=TUI_SPIN_S,
    )


def run(args: argparse.Namespace) -> int:
    """Bring the station up, run the app until the pilot quits, then take everything down."""
    from gcs.tui.app import make_app
    from gcs.tui.station_backend import StationBackend

    with StationSession(options_from_args(args)) as session:
        v = session.first
        backend = StationBackend(
            v.station, url=v.url,
            recording=str(v.recorder.path) if v.recorder is not None else None,
            dialect=v.link.dialect.value, signing=v.link.signing,
        )
        v.station.start()
        make_app(backend).run()
        if v.station.error is not None:
            print(f"quadgcs teleop: control loop stopped: {v.station.error}")
            return 1
    return 0
