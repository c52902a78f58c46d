"""`quadgcs mission run FILE`: fly a mission file's planner on a vehicle or in the kinematic world.

With no `--connect` it starts the bundled SITL with the file's world and vehicles; `--kinematic`
runs the same planner with exact moves (seconds). A line per planner step goes to stderr while
it runs (not with `--quiet`); the summary (or with `--json` one JSON object) goes to stdout.
Exit 0 when the goal is met (or an unscored run finished: nothing to score it against), 3 when
the mission failed, 2 for bad input, 1 for runtime faults.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from gcs.commands._vehicle_args import (
    add_connect_timeout_argument,
    add_forward_argument,
    add_foxglove_argument,
    connect_timeout,
)
from gcs.errors import MissionFailed, UsageError
from gcs.mission.options import RunOptions
from gcs.mission.runner import run_mission
from gcs.mission.spec import load_mission


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add the `mission` subcommand (with `run`)."""
    p = sub.add_parser("mission", help="run a mission file (EPBHA, flocking, radiation)",
                       description=__doc__)
    msub = p.add_subparsers(dest="mission_command", metavar="ACTION", help="what to do")
    r = msub.add_parser("run", help="fly a mission file", description=__doc__)
    r.add_argument("file", type=Path, help="mission TOML (see missions/)")
    r.add_argument("--connect", metavar="URL",
                   help="vehicle link (tcp:HOST:PORT, udpin:..., /dev/ttyUSB0[,baud]); "
                        "default: start the bundled SITL with the mission's world")
    add_connect_timeout_argument(r)
    r.add_argument("--arm-timeout", type=float, metavar="S",
                   help="ask each vehicle to arm again, showing its firmware's refusal, until "
                        "this long after the first request (default: the file's "
                        "flight.arm_timeout_s, else 30)")
    r.add_argument("--mocap", metavar="URL", help="motion-capture endpoint (tcp:HOST:PORT)")
    r.add_argument("--kinematic", action="store_true",
                   help="exact moves in the planners' kinematic world, no vehicle")
    r.add_argument("--speedup", type=float,
                   help="run the bundled SITL and the station's clock this many times faster "
                        "(default: the mission file's flight.speedup)")
    r.add_argument("--lockstep", action="store_true",
                   help="fly the bundled SITL in this process on simulated time: as fast as "
                        "the machine computes, the same mission for the same seed")
    r.add_argument("--seed", type=int, help="seed of the noise (kinematic world or SITL)")
    r.add_argument("--record", action=argparse.BooleanOptionalAction, default=True,
                   help="record to MCAP (default on)")
    r.add_argument("-o", "--output", type=Path, default=Path("flights"),
                   help="recording file or directory (default flights/)")
    r.add_argument("--plot", type=Path, help="radiation: picture path (default: next to the "
                                             "recording)")
    r.add_argument("--fix-failsafe", action="store_true",
                   help="let the station set the vehicles' failsafe parameters when the "
                        "pre-flight checks find that a silent link would not land them (see "
                        "fly --help); without it such a vehicle is refused")
    r.add_argument("--no-truth", dest="truth", action="store_false",
                   help="keep the world's sources and boxes from the station and the planner "
                        "(the SITL or kinematic world still simulates them) and score nothing "
                        "against them: as on a real floor")
    add_forward_argument(r)
    add_foxglove_argument(r)
    r.add_argument("--json", action="store_true", help="print the result as one JSON object")
    r.add_argument("-q", "--quiet", action="store_true", help="no progress lines")
    r.set_defaults(func=run)
    p.set_defaults(func=_no_action)


def _no_action(args: argparse.Namespace) -> int:
    raise UsageError("expected an action: mission run FILE")


def _progress(line: str) -> None:
    print(line, file=sys.stderr, flush=True)


def run(args: argparse.Namespace) -> int:
    """CLI entry: load, run, print; MissionFailed (exit 3) after printing when not reached."""
    if args.kinematic and (args.connect or args.mocap or args.forward or args.lockstep):
        raise UsageError("--kinematic flies no vehicle: drop --connect/--mocap/--forward/"
                         "--lockstep")
    if args.lockstep and args.speedup is not None:
        raise UsageError("--lockstep: --speedup cannot be used with it (lockstep flies the "
                         "bundled SITL in this process on simulated time)")
    if args.arm_timeout is not None and not 0 < args.arm_timeout <= 600:
        raise UsageError(f"--arm-timeout {args.arm_timeout:g}: expected 0 < S <= 600")
    if args.speedup is not None and not 0 < args.speedup <= 50:
        raise UsageError(f"--speedup {args.speedup}: expected 0 < speedup <= 50")
    spec = load_mission(args.file)
    options = RunOptions(kinematic=args.kinematic, connect=args.connect, mocap=args.mocap,
                         connect_timeout_s=connect_timeout(args),
                         arm_timeout_s=args.arm_timeout,
                         record=args.record, output=args.output, plot=args.plot,
                         speedup=args.speedup, seed=args.seed, fix_failsafe=args.fix_failsafe,
                         foxglove=args.foxglove, forward=tuple(args.forward),
                         truth=args.truth, lockstep=args.lockstep)
    report = run_mission(spec, options, None if (args.quiet or args.json) else _progress)
    if args.json:
        print(report.to_json(), flush=True)
    else:
        print("\n".join(report.summary_lines()), flush=True)
    if not report.ok:
        raise MissionFailed(f"mission {spec.name} failed: {report.reason}")
    return 0
