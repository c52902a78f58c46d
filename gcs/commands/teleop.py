"""`quadgcs teleop`: fly and watch one vehicle from a terminal.

With no `--connect` it starts the bundled SITL. The 25 ms loop runs in its own process (see
`gcs.tui.process_backend`); the Textual app only reads views and sends intents, so a slow
terminal never stretches a tick.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from gcs.commands._vehicle_args import add_vehicle_arguments, session_options
from gcs.errors import UsageError
from gcs.station.session import SessionOptions

if TYPE_CHECKING:
    from gcs.gamepad.driver import Gamepad

MAX_GAMEPAD_RATE_HZ = 250.0

MAX_TAKEOFF_ALT_M = 3.5

def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add the `teleop` subcommand."""
    p = sub.add_parser("teleop", help="fly one vehicle from the terminal (TUI)",
                       description=__doc__)
    add_vehicle_arguments(p)
    p.add_argument("--takeoff-alt", type=float, metavar="M",
                   help="where `h` from the floor climbs to (default 1.0 m; never below the "
                        "rangefinder's minimum range plus a margin, read from the vehicle)")
    p.add_argument("--gamepad", nargs="?", const="", default=None, metavar="NAME|INDEX",
                   help="fly with a gamepad (SDL2): the first pad, the one at INDEX, or the "
                        "first whose name contains NAME; it takes the sticks from the keyboard")
    p.add_argument("--gamepad-map", type=Path, metavar="FILE",
                   help="gamepad mapping TOML, tried before the bundled one (Xbox, DualShock, "
                        "Logitech F310, any pad in SDL's database)")
    p.add_argument("--gamepad-rate", type=float, metavar="HZ",
                   help="how often the gamepad is read (default: the mapping's poll_hz, 50)")
    p.set_defaults(func=run)


def options_from_args(args: argparse.Namespace) -> SessionOptions:
    """The session the flags ask for."""
    alt = getattr(args, "takeoff_alt", None)
    if alt is not None and not 0.0 < alt <= MAX_TAKEOFF_ALT_M:
        raise UsageError(f"--takeoff-alt {alt:g}: expected 0 < M <= {MAX_TAKEOFF_ALT_M:g} "
                         "(the sonar's trustworthy range)")
    return session_options(args, "teleop")


def open_gamepad(args: argparse.Namespace) -> Gamepad | None:
    """The pad the flags ask for, opened and checked before any vehicle is started (a bad
    mapping or a missing pad is one line, not a flight without sticks)."""
    selector = getattr(args, "gamepad", None)
    rate = getattr(args, "gamepad_rate", None)
    if selector is None:
        if getattr(args, "gamepad_map", None) is not None or rate is not None:
            raise UsageError("--gamepad-map and --gamepad-rate need --gamepad")
        return None
    if rate is not None and not 0.0 < rate <= MAX_GAMEPAD_RATE_HZ:
        raise UsageError(f"--gamepad-rate {rate:g}: expected 0 < HZ <= {MAX_GAMEPAD_RATE_HZ:g}")
    from gcs.gamepad.driver import Gamepad
    from gcs.gamepad.mapping import load_mappings
    from gcs.gamepad.sdl_pad import SdlPad

    return Gamepad(SdlPad(selector, load_mappings(args.gamepad_map), poll_hz=rate))


def run(args: argparse.Namespace) -> int:
    """Start the station process, run the app until the pilot quits, then take it all down."""
    from gcs.tui.app import make_app
    from gcs.tui.process_backend import ProcessBackend

    gamepad = open_gamepad(args)
    try:
        backend = ProcessBackend(options_from_args(args))
    except BaseException:
        if gamepad is not None:
            gamepad.close()
        raise
    try:
        make_app(backend, gamepad=gamepad).run()
    finally:
        backend.close()
        if gamepad is not None:
            gamepad.close()
    if backend.error is not None:
        text, code = backend.error
        print(f"quadgcs teleop: {text}", file=sys.stderr)
        return code
    return 0
