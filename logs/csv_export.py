"""One CSV per topic: a header row, then one row per message with flattened columns.

Nested objects flatten with dots (`acc_b.z`), arrays with indices (`channels_us.2`), so a
spreadsheet or pandas gets one plain column per number. The first two columns are the message's
log time as UTC seconds and its seconds since the recording's first message.
"""

from __future__ import annotations

import csv
import os
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

from logs.errors import RecordingError
from logs.reader import Recording


def flatten(message: Any, prefix: str = "") -> dict[str, Any]:
    """Nested dicts and lists → one level with dotted keys."""
    out: dict[str, Any] = {}
    if isinstance(message, Mapping):
        for key, value in message.items():
            out.update(flatten(value, f"{prefix}.{key}" if prefix else str(key)))
    elif isinstance(message, list):
        for i, value in enumerate(message):
            out.update(flatten(value, f"{prefix}.{i}" if prefix else str(i)))
    else:
        out[prefix or "value"] = message
    return out


def csv_name(topic: str) -> str:
    """"/vehicle/imu" → "vehicle_imu.csv"."""
    stem = "".join(c if c.isalnum() or c in "-_" else "_" for c in topic.strip("/"))
    return f"{stem or 'root'}.csv"


def export_csv(
    recording: Recording, out_dir: str | os.PathLike[str], topics: Iterable[str] | None = None
) -> dict[str, Path]:
    """Write one CSV per topic into `out_dir`; returns topic → file."""
    out = Path(out_dir)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise RecordingError(f"{out}: cannot create directory: {exc.strerror or exc}") from exc
    wanted = list(topics) if topics is not None else recording.topics
    rows: dict[str, list[dict[str, Any]]] = {t: [] for t in wanted}
    columns: dict[str, dict[str, None]] = {t: {} for t in wanted}
    start_ns = recording.start_ns
    for topic, log_ns, message in recording.messages(wanted):
        row = {
            "log_time_s": f"{log_ns // 1_000_000_000}.{log_ns % 1_000_000_000:09d}",
            "rel_time_s": f"{(log_ns - start_ns) / 1e9:.6f}",
        }
        row.update(flatten(message))
        rows[topic].append(row)
        for key in row:
            columns[topic].setdefault(key, None)
    written: dict[str, Path] = {}
    for topic in wanted:
        path = out / csv_name(topic)
        header = list(columns[topic]) or ["log_time_s", "rel_time_s"]
        try:
            with open(path, "w", newline="") as f:
                writer = csv.DictWriter(f, fieldnames=header, restval="")
                writer.writeheader()
                writer.writerows(rows[topic])
        except OSError as exc:
            raise RecordingError(f"{path}: cannot write: {exc.strerror or exc}") from exc
        written[topic] = path
    return written
