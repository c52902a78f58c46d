"""Flags every command that connects to a vehicle shares, and the session they describe."""

from __future__ import annotations

import argparse
from pathlib import Path

from firmware_link import DEFAULT_CONNECT_TIMEOUT_S
from gcs.errors import UsageError
from gcs.station.session import SessionOptions


def add_vehicle_arguments(p: argparse.ArgumentParser) -> None:
    """--connect, --mocap, the bundled SITL's choices, station config, signing, recording."""
    p.add_argument("--connect", metavar="URL",
                   help="vehicle link (tcp:HOST:PORT, udpin:..., /dev/ttyUSB0[,baud]); "
                        "default: start the bundled SITL")
    add_connect_timeout_argument(p)
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
    p.add_argument("--fix-failsafe", action="store_true",
                   help="let the station set the vehicle's failsafe parameters when the "
                        "pre-flight checks find that a silent link would not land it (4.x: "
                        "FS_OPTIONS bit 4 off, FS_GCS_ENABLE 5, FS_GCS_TIMEOUT under "
                        "RC_OVERRIDE_TIME; 3.2.1 with GPS: RTL_ALT 0); without it such a "
                        "vehicle is refused")
    add_forward_argument(p)
    add_foxglove_argument(p)


def add_connect_timeout_argument(p: argparse.ArgumentParser, default: object = None) -> None:
    """--connect-timeout S: how long --connect waits for a vehicle that is not up yet."""
    p.add_argument("--connect-timeout", metavar="S", type=float,
                   default=DEFAULT_CONNECT_TIMEOUT_S if default is None else default,
                   help="with --connect, wait this long for a vehicle that is not up yet "
                        "(its TCP port refusing, its serial device absent, no heartbeat), "
                        f"retrying (default {DEFAULT_CONNECT_TIMEOUT_S:g})")


def connect_timeout(args: argparse.Namespace) -> float:
    """The checked --connect-timeout."""
    value = float(getattr(args, "connect_timeout", DEFAULT_CONNECT_TIMEOUT_S))
    if not 0 < value <= 3600:
        raise UsageError(f"--connect-timeout {value:g}: expected 0 < S <= 3600")
    return value


def add_forward_argument(p: argparse.ArgumentParser) -> None:
    """--forward URL (repeatable): other ground stations watching through this one."""
    p.add_argument("--forward", metavar="URL", action="append", default=[],
                   help="let another ground station (QGroundControl, Mission Planner, MAVProxy) "
                        "share the vehicle: udpout:HOST:PORT, udpin:HOST:PORT or "
                        "tcpin:HOST:PORT; every vehicle frame goes out unchanged, its frames "
                        "go to the vehicle except RC overrides while quadgcs flies; repeatable")


def add_foxglove_argument(p: argparse.ArgumentParser, note: str = "") -> None:
    """--foxglove [HOST:]PORT: the live view (fly, teleop, mission run, replay)."""
    p.add_argument("--foxglove", metavar="[HOST:]PORT",
                   help="serve the flight live to Foxglove over its WebSocket protocol "
                        "(ws://HOST:PORT, the recording's topics); HOST defaults to 127.0.0.1, "
                        "use 0.0.0.0 to serve other machines; port 0 picks a free one" + note)


def session_options(args: argparse.Namespace, command: str) -> SessionOptions:
    """The session the shared flags ask for."""
    return SessionOptions(
        command=command, connect=args.connect, mocap=args.mocap, profile=args.profile,
        world=args.world, serial=args.serial, speedup=getattr(args, "speedup", 1.0),
        seed=args.seed, config=args.config, signing_key=args.signing_key, record=args.record,
        output=args.output, fix_failsafe=getattr(args, "fix_failsafe", False),
        foxglove=getattr(args, "foxglove", None),
        forward=tuple(getattr(args, "forward", None) or ()),
        connect_timeout_s=connect_timeout(args),
        takeoff_alt_m=getattr(args, "takeoff_alt", None),
    )
