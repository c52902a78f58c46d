"""`quadgcs teleop`: fly and watch one vehicle from a terminal.

With no `--connect` it starts the bundled SITL. The 25 ms loop runs in its own process (see
`gcs.tui.process_backend`); the Textual app only reads views and sends intents, so a slow
terminal never stretches a tick.
"""

from __future__ import annotations

import argparse
import sys

from gcs.commands._vehicle_args import add_vehicle_arguments, session_options
from gcs.session import SessionOptions


def register(sub: argparse._SubParsersAction) -> None:
    """Add the `teleop` subcommand."""
    p = sub.add_parser("teleop", help="fly one vehicle from the terminal (TUI)",
                       description=__doc__)
    add_vehicle_arguments(p)
    p.set_defaults(func=run)


def options_from_args(args: argparse.Namespace) -> SessionOptions:
    """The session the flags ask for."""
    return session_options(args, "teleop")


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
