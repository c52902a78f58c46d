"""`quadgcs logs check FILE…`: the automatic review of recordings (MCAP, or tlogs through their
import), a table of checks each PASS/WARN/FAIL/SKIP; exit 1 when any check failed, 2 on bad
input. `--against CAMPAIGN` places the flight among a campaign's runs (`logs.check.against`)."""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

from gcs.errors import UsageError
from gcs.flight_check import gather_file
from logs import RecordingError, open_recording
from logs.check import Status, ThresholdError, evaluate, load_thresholds, measure, worst
from logs.check.against import format_placements, place, settings_differences
from logs.check.html import write_html
from logs.check.table import format_table, to_json

RESULTS_NAME = "results.parquet"


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add `logs check`."""
    p = sub.add_parser("check", help="review recordings: link, loop, estimator, vibration, "
                       "control, power, events, hold; PASS/WARN/FAIL per check")
    p.add_argument("files", type=Path, nargs="+", metavar="FILE",
                   help="recording (.mcap) or MAVLink telemetry log (.tlog)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--html", type=Path, metavar="OUT",
                   help="write an HTML report with the plots beside each check")
    p.add_argument("--thresholds", type=Path, metavar="FILE",
                   help="TOML overriding the thresholds table (docs/log-check.md)")
    p.add_argument("--against", type=Path, metavar="CAMPAIGN",
                   help="a campaign's output directory (or its results.parquet): place each "
                        "flight's metrics in the campaign's distribution")
    p.set_defaults(func=cmd_check)


def read_campaign(path: Path) -> list[dict[str, Any]]:
    """The rows of a campaign's results (UsageError when there are none)."""
    results = path / RESULTS_NAME if path.is_dir() else path
    if not results.is_file():
        raise UsageError(f"{path}: no {RESULTS_NAME} (expected a campaign's output directory)")
    try:
        import pyarrow.parquet as pq

        rows = list(pq.read_table(results).to_pylist())
    except Exception as exc:  # pyarrow raises many types for a file that is not Parquet
        raise UsageError(f"{results}: not a campaign results file ({exc})") from exc
    if not any(k.startswith("check.") for row in rows for k in row):
        raise UsageError(f"{results}: the campaign kept no check metrics (fly it with "
                         "record = true so each run's recording is checked)")
    return rows


def campaign_settings(path: Path, rows: list[dict[str, Any]]) -> dict[str, Any] | None:
    """The station settings the campaign flew (its first kept recording's `/gcs/setup`), and
    None when it kept none."""
    root = path if path.is_dir() else path.parent
    for row in rows:
        recording = root / "flights" / f"{row.get('run_id')}.mcap"
        if row.get("status") != "ok" or not recording.is_file():
            continue
        try:
            for _topic, _ns, message in open_recording(recording).messages(["/gcs/setup"]):
                config = json.loads(str(message.get("config_json", "{}")))
                return config if isinstance(config, dict) else None
        except (RecordingError, ValueError):
            continue
    return None


def cmd_check(args: argparse.Namespace) -> int:
    """Check every file; print the tables (or JSON); write the HTML report if asked."""
    try:
        table = load_thresholds(args.thresholds)
    except ThresholdError as exc:
        raise UsageError(str(exc)) from exc
    campaign = read_campaign(args.against) if args.against is not None else None
    settings = campaign_settings(args.against, campaign) if campaign is not None else None
    varied = sorted({k for row in campaign or [] for k in row if k.startswith("station.")})
    reports: list[dict[str, Any]] = []
    texts: list[str] = []
    pages = []
    failed = False
    for path in args.files:
        try:
            fs = gather_file(path)
        except RecordingError as exc:
            raise UsageError(str(exc)) from exc
        measured = measure(fs)
        results = evaluate(measured, table)
        failed |= worst(results) is Status.FAIL
        report = to_json(str(path), results)
        text = format_table(str(path), results)
        placements = None
        if campaign is not None:
            placements = place(measured, campaign, table)
            differ = (settings_differences(fs.setup, settings, varied)
                      if settings is not None and fs.setup else [])
            report["against"] = {"campaign": str(args.against),
                                 "flagged": sum(p.flagged for p in placements),
                                 "settings_differ": differ,
                                 "metrics": [p.to_dict() for p in placements]}
            text += "\n" + format_placements(str(args.against), placements)
            if differ:
                text += ("\n  settings differ from the campaign's: " + "; ".join(differ))
            failed |= any(p.flagged for p in placements) or bool(differ)
        reports.append(report)
        texts.append(text)
        pages.append((str(path), fs, results, placements))
    if args.html is not None:
        try:
            write_html(args.html, pages)
        except OSError as exc:
            raise UsageError(f"{args.html}: cannot write: {exc.strerror or exc}") from exc
    if args.json:
        print(json.dumps({"status": "FAIL" if failed else "OK", "files": reports}, indent=2))
    else:
        print("\n\n".join(texts))
        if args.html is not None:
            print(f"wrote {args.html}")
    return 1 if failed else 0
