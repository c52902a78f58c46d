"""`quadgcs replay FILE`: play a recorded flight on its timeline, one status line per second.

Headless playback lives in `run_replay`; re-running a flight through the station's estimator and
controller (`--rerun`) belongs in its own function beside it.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from gcs.errors import UsageError
from logs import RecordingError, open_recording
from logs.replay import Player, run_headless


def register(subparsers: argparse._SubParsersAction) -> None:
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
    parser.set_defaults(func=run_replay)


def run_replay(args: argparse.Namespace) -> int:
    """Play the recording and print its summary lines."""
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


def run_screens(player: Player, path: Path, metadata: dict[str, object]) -> int:
    """Open the teleop screens on the recording: play/pause, speed, seek."""
    from gcs.tui.app import make_app
    from gcs.tui.replay_backend import ReplayBackend

    make_app(ReplayBackend(player, name=path.name, metadata=dict(metadata))).run()
    return 0
