"""`quadgcs replay FILE`: play a recorded flight on its timeline, one status line per second.

Headless playback lives in `run_replay`; `--rerun` (`run_rerun`) feeds the recorded sensor data
through fresh estimator and altitude-controller instances, optionally with other parameters
(`--gains`), and reports how their outputs differ from the recorded ones (gcs/rerun.py).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from gcs.commands._vehicle_args import add_foxglove_argument
from gcs.errors import UsageError
from logs import RecordingError, open_recording
from logs.replay import Player, ReplayMessage, run_headless


def register(subparsers: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add `replay`."""
    parser = subparsers.add_parser(
        "replay", help="play a recorded flight on the teleop screens (or headless)")
    parser.add_argument("file", type=Path, help="recording (.mcap)")
    pace = parser.add_mutually_exclusive_group()
    pace.add_argument("--speed", type=float, default=1.0, help="playback rate (default 1)")
    pace.add_argument("--max", action="store_true", help="as fast as possible (headless)")
    parser.add_argument("--headless", action="store_true",
                        help="print summary lines instead of opening the screens (the default "
                             "when output is not a terminal)")
    parser.add_argument("--rerun", action="store_true",
                        help="re-run the estimator and altitude controller on the recorded "
                             "sensor data and report how their outputs differ from the recording")
    parser.add_argument("--gains", action="append", default=[], metavar="SPEC",
                        help="with --rerun: parameter changes, 'alt.kp=1.2,alt.ki=0.3' (dotted "
                             "station-config keys; alt. = altitude.gains., est. = estimator., "
                             "pos. = position.) or a station-config TOML file; repeatable")
    parser.add_argument("--json", action="store_true", help="with --rerun: one JSON object")
    add_foxglove_argument(parser, "; the replay then plays headless at --speed (or --max)")
    parser.set_defaults(func=run_replay)


def run_replay(args: argparse.Namespace) -> int:
    """Play the recording and print its summary lines (or rerun it with `--rerun`)."""
    if args.rerun:
        return run_rerun(args)
    if args.gains or args.json:
        raise UsageError("--gains and --json go with --rerun")
    if args.foxglove is not None:
        return run_live(args)
    try:
        recording = open_recording(args.file)
        player = Player(recording, speed=args.speed)
    except RecordingError as exc:
        raise UsageError(str(exc)) from exc
    if not (args.headless or args.max) and sys.stdout.isatty():
        return run_screens(player, args.file, recording.metadata)
    report = run_headless(player, sys.stdout, as_fast_as_possible=args.max)
    print(f"replayed {report.messages} messages, {report.duration_s:.1f} s of flight")
    return 0


def run_live(args: argparse.Namespace) -> int:
    """Play the recording on its timeline (headless) and serve every message to Foxglove with
    its recorded schema and log time, as the flight itself served them."""
    from gcs.foxglove_feed import open_live
    from logs.encoding import encode_json

    try:
        recording = open_recording(args.file)
        player = Player(recording, speed=args.speed)
    except RecordingError as exc:
        raise UsageError(str(exc)) from exc
    schemas = {topic: recording.schema(topic) for topic in recording.topics}
    live = open_live(args.foxglove)
    print(f"foxglove: live view on {live.url}", file=sys.stderr, flush=True)
    try:
        def publish(msg: ReplayMessage) -> None:
            name, schema = schemas[msg.topic]
            live.publish(msg.topic, name, schema, msg.log_time_ns, encode_json(msg.message))

        report = run_headless(player, sys.stdout, as_fast_as_possible=args.max,
                              on_message=publish)
    finally:
        live.close()
    print(f"replayed {report.messages} messages, {report.duration_s:.1f} s of flight")
    return 0


def run_screens(player: Player, path: Path, metadata: dict[str, object]) -> int:
    """Open the teleop screens on the recording: play/pause, speed, seek."""
    from gcs.tui.app import make_app
    from gcs.tui.replay_backend import ReplayBackend

    make_app(ReplayBackend(player, name=path.name, metadata=dict(metadata))).run()
    return 0


def run_rerun(args: argparse.Namespace) -> int:
    """Re-run the flight's estimator and controller; print the per-signal differences."""
    from gcs.rerun import (
        apply_overrides,
        changed_parameters,
        compare,
        format_report,
        load_flight,
        parse_gains,
        rerun,
    )

    try:
        recording = open_recording(args.file)
    except RecordingError as exc:
        raise UsageError(str(exc)) from exc
    flight = load_flight(recording)
    config = flight.config
    for spec in args.gains:
        config = apply_overrides(config, parse_gains(spec))
    report = compare(flight, rerun(flight, config), changed_parameters(flight.config, config))
    if args.json:
        print(json.dumps(report.to_jsonable()))
    else:
        print("\n".join(format_report(report, args.file.name)))
    return 0
