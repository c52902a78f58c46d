"""`quadgcs logs info|export|recover|plot|import-tlog|check`: look into, convert and review
flight recordings."""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Callable
from pathlib import Path

from gcs.commands import logs_check
from gcs.errors import RuntimeFault, UsageError
from logs import Recording, RecordingError, open_recording
from logs.csv_export import export_csv
from logs.info import format_summary, summarize
from logs.plot import PlotUnavailable, plot_flight
from logs.recover import recover
from logs.tlog import export_tlog, import_tlog


def register(subparsers: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add `logs` and its subcommands."""
    parser = subparsers.add_parser(
        "logs", help="inspect, export, recover and plot flight recordings (MCAP)"
    )
    sub = parser.add_subparsers(dest="logs_command", metavar="ACTION", help="what to do")
    parser.set_defaults(func=_missing_action(parser))

    info = sub.add_parser("info", help="duration, topics, counts, rates, gaps, link losses")
    info.add_argument("file", type=Path, help="recording (.mcap)")
    info.add_argument("--json", action="store_true", help="print JSON instead of a table")
    info.set_defaults(func=cmd_info)

    export = sub.add_parser("export", help="export raw MAVLink as a tlog and/or topics as CSV")
    export.add_argument("file", type=Path, help="recording (.mcap)")
    export.add_argument("--tlog", type=Path, metavar="OUT", help="write a MAVLink .tlog")
    export.add_argument("--csv", type=Path, metavar="DIR", help="write one CSV per topic")
    export.add_argument(
        "--topic", action="append", metavar="TOPIC", help="CSV: only this topic (repeatable)"
    )
    export.set_defaults(func=cmd_export)

    rec = sub.add_parser("recover", help="make a truncated recording valid and indexed again")
    rec.add_argument("file", type=Path, help="truncated recording (.mcap)")
    rec.add_argument("-o", "--output", type=Path, help="output (default FILE.recovered.mcap)")
    rec.set_defaults(func=cmd_recover)

    plot = sub.add_parser("plot", help="altitude, throttle and vertical acceleration plot")
    plot.add_argument("file", type=Path, help="recording (.mcap)")
    plot.add_argument("-o", "--output", type=Path, default=Path("flight.png"), help="image")
    plot.set_defaults(func=cmd_plot)

    imp = sub.add_parser("import-tlog", help="copy a tlog's raw MAVLink frames into MCAP")
    imp.add_argument("tlog", type=Path, help="MAVLink telemetry log (.tlog)")
    imp.add_argument("-o", "--output", type=Path, required=True, help="output .mcap")
    imp.set_defaults(func=cmd_import_tlog)

    logs_check.register(sub)


def _missing_action(parser: argparse.ArgumentParser) -> Callable[[argparse.Namespace], int]:
    def run(_args: argparse.Namespace) -> int:
        parser.print_help(sys.stderr)
        return 2

    return run


def _open(path: Path) -> Recording:
    try:
        return open_recording(path)
    except RecordingError as exc:
        raise UsageError(str(exc)) from exc


def cmd_info(args: argparse.Namespace) -> int:
    """Print what a recording holds."""
    try:
        summary = summarize(_open(args.file))
    except RecordingError as exc:
        raise UsageError(str(exc)) from exc
    if args.json:
        print(json.dumps(summary.to_dict(), indent=2))
    else:
        print(format_summary(summary))
    return 0


def cmd_export(args: argparse.Namespace) -> int:
    """Write a tlog and/or CSV files."""
    if args.tlog is None and args.csv is None:
        raise UsageError("logs export: give --tlog OUT and/or --csv DIR")
    recording = _open(args.file)
    try:
        if args.tlog is not None:
            n = export_tlog(recording, args.tlog)
            print(f"wrote {n} MAVLink frames to {args.tlog}")
        if args.csv is not None:
            files = export_csv(recording, args.csv, args.topic)
            print(f"wrote {len(files)} CSV files to {args.csv}")
    except RecordingError as exc:
        raise UsageError(str(exc)) from exc
    return 0


def cmd_recover(args: argparse.Namespace) -> int:
    """Rewrite the whole chunks of a truncated recording into a valid file."""
    try:
        result = recover(args.file, args.output)
    except RecordingError as exc:
        raise UsageError(str(exc)) from exc
    span_s = (result.last_ns - result.first_ns) / 1e9 if result.messages else 0.0
    state = "was truncated" if result.was_truncated else "was already complete"
    print(
        f"{args.file} {state}: kept {result.messages} messages on {result.topics} topics "
        f"({span_s:.1f} s) in {result.output}"
    )
    return 0


def cmd_plot(args: argparse.Namespace) -> int:
    """Draw the flight."""
    recording = _open(args.file)
    try:
        out = plot_flight(recording, args.output)
    except PlotUnavailable as exc:
        raise RuntimeFault(str(exc)) from exc
    except RecordingError as exc:
        raise UsageError(str(exc)) from exc
    print(f"wrote {out}")
    return 0


def cmd_import_tlog(args: argparse.Namespace) -> int:
    """Copy a tlog's frames onto /mavlink/rx and /mavlink/tx."""
    try:
        result = import_tlog(args.tlog, args.output)
    except RecordingError as exc:
        raise UsageError(str(exc)) from exc
    print(f"imported {result.rx} rx and {result.tx} tx frames into {result.output}")
    return 0
